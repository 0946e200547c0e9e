#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-2-Clause
"""ctest distribution_release: cmake/make_release.py (the `release` target's
program) writes a release folder, and this checks it:

1. SHA256SUMS lists every other file of the folder, each with its sha256,
   and the check catches a changed byte and a missing file;
2. the contents: the four FMUs (this build's archives byte for byte, their
   model descriptions at the project's version), the installed C package
   (pkm.h, libpkm shared with its SOVERSION link (pkm.h's PKM_ABI_VERSION)
   and static, the CMake and
   pkg-config packages, the FMUs, the licences), the sdist (PKG-INFO at the
   version, the sources, no build tree), LICENSE, CHANGELOG.md, the manifest
   (saying whether the FMUs are merged or the host's);
3. a second run gives the same bytes for everything but the sdist (its
   archive dates are the build tool's).
The wheel is left out (--no-wheel): its CMake build takes minutes, and
ctest distribution_wheel builds and checks it.

usage: check_release.py --make-release PY --build DIR --source DIR --version X.Y.Z
                        --platforms ON|OFF --work DIR --stamp STAMP.json
"""
import argparse
import hashlib
import json
import re
import shutil
import subprocess
import sys
import tarfile
import zipfile
from pathlib import Path

MODELS = ["PKM4PUU", "PKM4PUU_Inverse"]


def fail(msg):
    print(f"check_release: FAIL: {msg}", flush=True)
    sys.exit(1)


def sha256(path):
    return hashlib.sha256(path.read_bytes()).hexdigest()


def sum_problems(folder):
    """What `sha256sum -c` would say, plus files SHA256SUMS does not list."""
    problems, listed = [], set()
    for line in (folder / "SHA256SUMS").read_text().splitlines():
        m = re.fullmatch(r"([0-9a-f]{64})  (\S+)", line)
        if not m:
            problems.append(f"malformed line {line!r}")
            continue
        listed.add(m.group(2))
        p = folder / m.group(2)
        if not p.is_file():
            problems.append(f"{m.group(2)}: listed, missing")
        elif sha256(p) != m.group(1):
            problems.append(f"{m.group(2)}: sha256 differs")
    present = {p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file()} - {"SHA256SUMS"}
    problems += [f"{f}: not in SHA256SUMS" for f in sorted(present - listed)]
    return problems


def make(args, out):
    cmd = [sys.executable, args.make_release, "--build", args.build, "--source", args.source, "--version",
           args.version, "--platforms", args.platforms, "--out", out, "--no-wheel", "--stamp", args.stamp]
    r = subprocess.run([str(c) for c in cmd], capture_output=True, text=True)
    print(r.stdout, r.stderr, sep="", flush=True)
    if r.returncode != 0:
        fail(f"make_release.py failed (exit {r.returncode})")
    return Path(out) / f"pkm4puu-{args.version}"


def check_fmu(path, version):
    with zipfile.ZipFile(path) as z:
        md = z.read("modelDescription.xml").decode()
        names = z.namelist()
    if not re.search(rf'<fmiModelDescription[^>]*\sversion="{re.escape(version)}"', md):
        fail(f"{path}: its modelDescription.xml is not at version {version}")
    if not any(n.startswith("documentation/licenses/") for n in names):
        fail(f"{path}: no documentation/licenses/")


def check_contents(folder, args):
    v, build, merged = args.version, Path(args.build), args.platforms in ("ON", "1")
    for name in ("LICENSE", "CHANGELOG.md", "README.md", "MANIFEST.txt"):
        if not (folder / name).is_file():
            fail(f"no {name}")
    for fmi in (2, 3):
        for m in MODELS:
            rel = f"fmi{fmi}/{m}.fmu"
            built = build / "dist" / rel if merged else build / (f"{m}.fmu" if fmi == 2 else f"fmi3/{m}.fmu")
            if sha256(folder / rel) != sha256(built):
                fail(f"{rel} is not the build's {built}")
            check_fmu(folder / rel, v)
    manifest = (folder / "MANIFEST.txt").read_text()
    wanted = "merged: every platform" if merged else "configured with PKM_PLATFORMS=OFF"
    if wanted not in manifest or "wheel (python/): left out" not in manifest:
        fail(f"MANIFEST.txt does not say {wanted!r} and that the wheel is left out:\n{manifest}")

    c_pkgs = list((folder / "c").glob(f"pkm4puu-{v}-*.tar.gz"))
    if len(c_pkgs) != 1:
        fail(f"c/ holds {c_pkgs}, not one C package")
    top = c_pkgs[0].name[: -len(".tar.gz")]
    with tarfile.open(c_pkgs[0]) as t:
        members = {m.name: m for m in t.getmembers()}
        header = (Path(args.source) / "include" / "pkm4puu" / "pkm.h").read_text()
        abi = re.search(r"^#define PKM_ABI_VERSION (\d+)$", header, re.M).group(1)
        need = ["include/pkm4puu/pkm.h", "include/pkm4puu/version.h", "lib/libpkm.a", f"lib/libpkm.so.{abi}.0.0",
                "lib/cmake/pkm4puu/pkm4puuConfig.cmake", "lib/cmake/pkm4puu/pkm4puuConfigVersion.cmake",
                "lib/pkgconfig/pkm4puu.pc", "share/doc/pkm4puu/LICENSE"]
        need += [f"share/pkm4puu/fmi{fmi}/{m}.fmu" for fmi in (2, 3) for m in MODELS]
        missing = [n for n in need if f"{top}/{n}" not in members]
        if missing:
            fail(f"{c_pkgs[0].name} lacks {missing}")
        so = members.get(f"{top}/lib/libpkm.so.{abi}")
        if so is None or not so.issym() or so.linkname != f"libpkm.so.{abi}.0.0":
            fail(f"{c_pkgs[0].name}: lib/libpkm.so.{abi} is not the SOVERSION link to libpkm.so.{abi}.0.0")
        for fmi in (2, 3):
            for m in MODELS:
                data = t.extractfile(members[f"{top}/share/pkm4puu/fmi{fmi}/{m}.fmu"]).read()
                if hashlib.sha256(data).hexdigest() != sha256(folder / f"fmi{fmi}/{m}.fmu"):
                    fail(f"{c_pkgs[0].name}: share/pkm4puu/fmi{fmi}/{m}.fmu is not the release's")
        epoch = json.loads(Path(args.stamp).read_text())["epoch"]
        if any(m.mtime != epoch for m in members.values()):
            fail(f"{c_pkgs[0].name}: an entry not dated {epoch} (the commit's date)")

    sdist = folder / "python" / f"pkm4puu-{v}.tar.gz"
    if not sdist.is_file():
        fail(f"no {sdist.relative_to(folder)}")
    with tarfile.open(sdist) as t:
        names = set(t.getnames())
        pkg_info = t.extractfile(f"pkm4puu-{v}/PKG-INFO").read().decode()
    if not re.search(rf"^Version: {re.escape(v)}$", pkg_info, re.M):
        fail(f"the sdist's PKG-INFO is not at version {v}")
    for n in ("pyproject.toml", "CMakeLists.txt", "include/pkm4puu/pkm.h", "python/pkm4puu/__init__.py", "LICENSE"):
        if f"pkm4puu-{v}/{n}" not in names:
            fail(f"the sdist lacks {n}")
    stray = sorted(n for n in names if re.match(rf"pkm4puu-{re.escape(v)}/(build|\.venv|results)(/|$)", n))
    if stray:
        fail(f"the sdist holds build output: {stray[:5]}")
    print(f"check_release: contents as expected ({len(c_pkgs)} C package with {len(members)} entries, "
          f"sdist with {len(names)} entries)", flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    for a in ("--make-release", "--build", "--source", "--version", "--platforms", "--work", "--stamp"):
        ap.add_argument(a, required=True)
    args = ap.parse_args()
    work = Path(args.work)
    shutil.rmtree(work, ignore_errors=True)
    print("check_release: the wheel is left out (--no-wheel): its CMake build takes minutes; "
          "ctest distribution_wheel builds and checks it", flush=True)

    folder = make(args, work / "a")
    problems = sum_problems(folder)
    if problems:
        fail(f"SHA256SUMS: {problems}")
    check_contents(folder, args)

    # The sums catch a changed byte and a missing file (on a copy).
    copy = work / "tampered"
    shutil.copytree(folder, copy)
    fmu = copy / "fmi2" / "PKM4PUU.fmu"
    data = bytearray(fmu.read_bytes())
    data[len(data) // 2] ^= 0x01
    fmu.write_bytes(bytes(data))
    (copy / "LICENSE").unlink()
    got = sum_problems(copy)
    if got != ["fmi2/PKM4PUU.fmu: sha256 differs", "LICENSE: listed, missing"] and \
            sorted(got) != sorted(["fmi2/PKM4PUU.fmu: sha256 differs", "LICENSE: listed, missing"]):
        fail(f"the sums did not catch a flipped byte and a deleted file: {got}")

    # Reproducible: a second run, the same bytes (the sdist aside).
    again = make(args, work / "b")
    differ = [line for line, other in zip((folder / "SHA256SUMS").read_text().splitlines(),
                                          (again / "SHA256SUMS").read_text().splitlines())
              if line != other and not line.endswith(f"python/pkm4puu-{args.version}.tar.gz")]
    if differ:
        fail(f"a second run differs: {differ}")
    print("check_release: PASS (sums, contents, tamper detection, second run identical but the sdist)")


if __name__ == "__main__":
    main()
