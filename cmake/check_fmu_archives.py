# SPDX-License-Identifier: BSD-2-Clause
"""Reads every shipped FMU archive of a build and fails on one that lacks a
licence its contents need, or whose model description does not carry the
project's version, copyright, licence and generation stamp.

usage: check_fmu_archives.py --build DIR --version X.Y.Z --licenses DIR --license FILE [FMU...]

Archives: the FMUs given, else every one of DIR/*.fmu, DIR/fmi3/*.fmu and
DIR/dist/fmi2|fmi3/*.fmu (the merged ones, when built). The notices each
part of an archive needs (documentation/licenses/<name>, byte for byte the
repository's copy):
  every archive        LICENSE.txt (the project's, --license)
  a binary             SUNDIALS.txt (CVODE linked statically),
                       Eigen.txt (its templates compiled in)
  a Linux or Windows   GCC-runtime-exception.txt (libstdc++ and libgcc
  binary               linked statically)
  a Windows binary     mingw-w64.txt (its runtime and winpthreads)
  sources/             Eigen.txt (Eigen's headers copied in)
The platform is read from the binary's folder (FMI 2.0: linux64, win64,
darwin64; FMI 3.0: x86_64-linux, aarch64-linux, x86_64-windows, ...).
"""
import argparse
import re
import sys
import zipfile
from pathlib import Path
from xml.etree import ElementTree

BINARY = ("SUNDIALS.txt", "Eigen.txt")
GCC = ("GCC-runtime-exception.txt",)
MINGW = ("mingw-w64.txt",)


def needed(names):
    """{notice: why} for the archive's file names."""
    need = {"LICENSE.txt": "the project"}
    for name in names:
        m = re.match(r"binaries/([^/]+)/[^/]+$", name)
        if m:
            platform = m.group(1)
            extra = BINARY
            if "linux" in platform or "win" in platform:
                extra += GCC
            if "win" in platform:
                extra += MINGW
            for notice in extra:
                need.setdefault(notice, f"binaries/{platform}")
        elif name.startswith("sources/"):
            need.setdefault("Eigen.txt", "sources/")
    return need


def check_model_description(xml, version):
    root = ElementTree.fromstring(xml)
    a = root.attrib
    bad = []
    expect = {"version": version, "copyright": "Copyright (c) 2026 The PKM4PUU authors", "license": "BSD-2-Clause"}
    for key, value in expect.items():
        if a.get(key) != value:
            bad.append(f"modelDescription {key}={a.get(key)!r}, expected {value!r}")
    if not re.fullmatch(rf"PKM4PUU {re.escape(version)}( \(commit [0-9a-f]{{7,40}}\))?", a.get("generationTool", "")):
        bad.append(f"modelDescription generationTool={a.get('generationTool')!r}, expected 'PKM4PUU {version} (commit ...)'")
    if not re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ", a.get("generationDateAndTime", "")):
        bad.append(f"modelDescription generationDateAndTime={a.get('generationDateAndTime')!r}, expected a UTC date")
    return bad


def check(fmu, version, texts):
    with zipfile.ZipFile(fmu) as z:
        names = z.namelist()
        bad = check_model_description(z.read("modelDescription.xml"), version)
        for notice, why in sorted(needed(names).items()):
            entry = f"documentation/licenses/{notice}"
            if entry not in names:
                bad.append(f"{entry} missing ({why} needs it)")
            elif z.read(entry) != texts[notice]:
                bad.append(f"{entry} differs from the repository's copy")
    return bad


def main():
    ap = argparse.ArgumentParser()
    for option in ("--build", "--version", "--licenses", "--license"):
        ap.add_argument(option, required=True)
    ap.add_argument("fmus", nargs="*")
    a = ap.parse_args()
    build = Path(a.build)
    fmus = [Path(f) for f in a.fmus] or sorted(
        [*build.glob("*.fmu"), *build.glob("fmi3/*.fmu"), *build.glob("dist/fmi[23]/*.fmu")])
    if not fmus:
        sys.exit(f"no FMU archive in {build}")
    texts = {p.name: p.read_bytes() for p in Path(a.licenses).glob("*.txt")}
    texts["LICENSE.txt"] = Path(a.license).read_bytes()
    failed = False
    for fmu in fmus:
        bad = check(fmu, a.version, texts)
        print(f"{fmu}: {'ok' if not bad else 'FAILED'}")
        for b in bad:
            print(f"  {b}")
        failed |= bool(bad)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
