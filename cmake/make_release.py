#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-2-Clause
"""The release (`cmake --build build --target release`): one folder
<out>/pkm4puu-<version>/ holding

    fmi2/<model>.fmu, fmi3/<model>.fmu   the FMUs: merged (every platform and
                                         the sources) under PKM_PLATFORMS, else
                                         the host's (the manifest says which)
    python/pkm4puu-<version>-*.whl       the wheel (pip wheel; --no-wheel leaves it out)
    python/pkm4puu-<version>.tar.gz      the sdist (python -m build --sdist)
    c/pkm4puu-<version>-<system>.tar.gz  the installed C package (cmake --install
                                         into a staging prefix): pkm.h, libpkm,
                                         the CMake and pkg-config packages, the FMUs
    LICENSE, CHANGELOG.md, README.md, MANIFEST.txt
    SHA256SUMS                           `sha256sum -c SHA256SUMS` checks every file

usage: make_release.py --build DIR --source DIR --version X.Y.Z --platforms ON|OFF
                       --out DIR [--no-wheel] [--stamp STAMP.json]
The archives written here are dated the build's source stamp's epoch (the
commit's date, as the FMUs are: cmake/source_stamp.cmake), with owners and
order fixed: the same inputs give the same bytes; the manifest names the
stamp's commit.
"""
import argparse
import gzip
import hashlib
import io
import platform
import shutil
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path

from pack_fmu import read_stamp  # beside this script, which Python puts first on the import path

MODELS = ["PKM4PUU", "PKM4PUU_Inverse"]


def fail(msg):
    sys.exit(f"make_release: {msg}")


def run(cmd, **kw):
    r = subprocess.run([str(c) for c in cmd], capture_output=True, text=True, **kw)
    if r.returncode != 0:
        fail(f"{' '.join(map(str, cmd))} failed (exit {r.returncode}):\n{r.stdout}{r.stderr}")
    return r


def sha256(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def reproducible_tar_gz(src_dir, dest, top, epoch):
    """src_dir's tree as dest (.tar.gz) under the folder `top`: sorted entries,
    every date `epoch`, owner root, no gzip name or date."""
    buf = io.BytesIO()
    with tarfile.open(fileobj=buf, mode="w", format=tarfile.PAX_FORMAT) as tar:
        for p in sorted(Path(src_dir).rglob("*")):
            info = tar.gettarinfo(str(p), arcname=f"{top}/{p.relative_to(src_dir).as_posix()}")
            info.mtime, info.uid, info.gid, info.uname, info.gname = epoch, 0, 0, "root", "root"
            if info.isfile():
                with open(p, "rb") as f:
                    tar.addfile(info, f)
            else:
                tar.addfile(info)
    with open(dest, "wb") as raw, gzip.GzipFile(filename="", mode="wb", fileobj=raw, mtime=0) as gz:
        gz.write(buf.getvalue())


def write_sums(folder):
    """SHA256SUMS of every other file of the folder, in sha256sum's format."""
    files = sorted(p for p in folder.rglob("*") if p.is_file() and p.name != "SHA256SUMS")
    lines = [f"{sha256(p)}  {p.relative_to(folder).as_posix()}" for p in files]
    (folder / "SHA256SUMS").write_text("\n".join(lines) + "\n")
    return len(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", required=True, type=Path)
    ap.add_argument("--source", required=True, type=Path)
    ap.add_argument("--version", required=True)
    ap.add_argument("--platforms", required=True, choices=["ON", "OFF", "1", "0"])
    ap.add_argument("--out", required=True, type=Path)
    ap.add_argument("--no-wheel", action="store_true", help="leave the wheel out (its CMake build takes minutes)")
    ap.add_argument("--stamp", help="the build's source stamp: the archives' date and the commit for the manifest")
    args = ap.parse_args()
    epoch, commit = read_stamp(args.stamp)
    build, source = args.build.resolve(), args.source.resolve()
    merged = args.platforms in ("ON", "1")
    name = f"pkm4puu-{args.version}"
    folder = args.out.resolve() / name
    if folder.exists():
        shutil.rmtree(folder)
    folder.mkdir(parents=True)
    print(f"make_release: writing {folder}", flush=True)

    # 1. The FMUs.
    for v in (2, 3):
        (folder / f"fmi{v}").mkdir()
        for m in MODELS:
            if merged:
                src = build / "dist" / f"fmi{v}" / f"{m}.fmu"
            else:
                src = build / (f"{m}.fmu" if v == 2 else f"fmi3/{m}.fmu")
            if not src.is_file():
                fail(f"no {src}: build the FMUs first")
            shutil.copy2(src, folder / f"fmi{v}" / f"{m}.fmu")

    # 2. The installed C package, archived.
    system = f"{platform.system().lower()}-{platform.machine()}"
    c_name = f"{name}-{system}"
    (folder / "c").mkdir()
    with tempfile.TemporaryDirectory(prefix="pkm-release-") as tmp:
        staging = Path(tmp) / "prefix"
        run(["cmake", "--install", build, "--prefix", staging])
        reproducible_tar_gz(staging, folder / "c" / f"{c_name}.tar.gz", c_name, epoch)

        # 3. The sdist and the wheel.
        (folder / "python").mkdir()
        run([sys.executable, "-m", "build", "--sdist", "--outdir", folder / "python", source], cwd=tmp)
        wheel_note = "left out (--no-wheel: its CMake build takes minutes; `cmake --build build --target release` builds it)"
        if not args.no_wheel:
            run([sys.executable, "-m", "pip", "wheel", "--disable-pip-version-check", "--no-deps", "-w",
                 folder / "python", source])
            wheel, = (folder / "python").glob(f"pkm4puu-{args.version}-*.whl")
            wheel_note = f"{wheel.name} (pip wheel; `auditwheel repair` retags it manylinux, ctest distribution_wheel)"

    # 4. The front matter, the manifest, the sums.
    for f in ("LICENSE", "CHANGELOG.md", "README.md"):
        shutil.copy2(source / f, folder / f)
    fmus = ("merged: every platform (Linux x86-64, Windows x64; Linux aarch64 in FMI 3.0) and the sources "
            "(configured with PKM_PLATFORMS=ON)") if merged else (
            "this build machine's platform only (" + system + "): configured with PKM_PLATFORMS=OFF, so the "
            "archives hold no Windows or aarch64 binaries and no sources; configure with -DPKM_PLATFORMS=ON "
            "for the merged archives")
    manifest = [
        f"PKM4PUU {args.version}",
        f"commit: {commit or 'unknown'}",
        f"FMUs (fmi2/, fmi3/): {fmus}",
        f"wheel (python/): {wheel_note}",
        f"sdist (python/): {name}.tar.gz",
        f"C package (c/): {c_name}.tar.gz, cmake --install of the build (include/, lib/, lib/cmake/pkm4puu/, "
        "lib/pkgconfig/, share/pkm4puu/, share/doc/pkm4puu/)",
        "check: sha256sum -c SHA256SUMS",
    ]
    (folder / "MANIFEST.txt").write_text("\n".join(manifest) + "\n")
    n = write_sums(folder)
    print("\n".join(manifest), flush=True)
    print(f"make_release: {folder}: {n} files, SHA256SUMS written", flush=True)


if __name__ == "__main__":
    main()
