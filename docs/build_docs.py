#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-2-Clause
"""Builds the documentation site from docs/ with every warning an error.

    python docs/build_docs.py --build build [--out build/docs/html]

1. Doxygen reads pkm.h's comments into XML (breathe renders the C API page
   from it: no signature is copied by hand).
2. The FMU reference pages come from the build: <build>/docs/generated/<id>.md,
   written by <id>_files --markdown from the variable tables (the same source
   as the model descriptions and the FMUs' documentation/index.html).
3. sphinx-build -W --keep-going, on a fresh environment (-E) so that every
   page is read and every warning shows on every run.
Exit status 1 on any warning or error; prints the wall time of each step.
Needs docs/requirements.txt and doxygen (scripts/setup.sh --for-build).
"""
import argparse
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
MODELS = ["PKM4PUU", "PKM4PUU_Inverse"]

DOXYFILE = """
PROJECT_NAME = pkm4puu
OUTPUT_DIRECTORY = {out}
INPUT = {header}
FILE_PATTERNS = *.h
GENERATE_XML = YES
GENERATE_HTML = NO
GENERATE_LATEX = NO
OPTIMIZE_OUTPUT_FOR_C = YES
ENABLE_PREPROCESSING = YES
MACRO_EXPANSION = YES
EXPAND_ONLY_PREDEF = YES
PREDEFINED = PKM_API=
EXTRACT_ALL = YES
QUIET = YES
WARN_IF_UNDOCUMENTED = NO
WARN_AS_ERROR = FAIL_ON_WARNINGS
"""


def step(name, fn):
    t0 = time.monotonic()
    fn()
    dt = time.monotonic() - t0
    print(f"build_docs: {name}: {dt:.1f} s", flush=True)
    return dt


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", required=True, type=Path, help="the CMake build tree (its docs/generated/)")
    ap.add_argument("--out", type=Path, help="HTML output (default BUILD/docs/html)")
    ap.add_argument("--doxygen", default="doxygen", help="the doxygen program")
    args = ap.parse_args()
    build = args.build.resolve()
    out = (args.out or build / "docs" / "html").resolve()
    work = build / "docs"
    generated = work / "generated"
    doxygen = shutil.which(args.doxygen)
    if doxygen is None:
        sys.exit(f"build_docs: no {args.doxygen} (apt-get install doxygen; scripts/setup.sh --for-build does)")
    try:
        import breathe, furo, myst_parser, sphinx  # noqa: F401,E401
    except ImportError as e:
        sys.exit(f"build_docs: {e.name} is missing: pip install -r docs/requirements.txt "
                 "(scripts/setup.sh --for-build installs it into .venv)")
    missing = [m for m in MODELS if not (generated / f"{m}.md").is_file()]
    if missing:
        sys.exit(f"build_docs: no {', '.join(f'{generated}/{m}.md' for m in missing)}: build the "
                 f"model description targets first (cmake --build {build})")

    total = time.monotonic()
    xml = work / "doxygen"

    def run_doxygen():
        shutil.rmtree(xml, ignore_errors=True)
        xml.mkdir(parents=True)
        cfg = DOXYFILE.format(out=xml, header=ROOT / "src" / "pkm4puu" / "pkm.h")
        subprocess.run([doxygen, "-"], input=cfg, text=True, check=True)

    def run_sphinx():
        env = dict(os.environ, PKM_DOCS_DOXYGEN_XML=str(xml / "xml"), PKM_DOCS_GENERATED=str(generated))
        cmd = [sys.executable, "-m", "sphinx", "-b", "html", "-W", "--keep-going", "-E", "-q",
               "-d", str(work / "doctrees"), str(DOCS), str(out)]
        r = subprocess.run(cmd, env=env)
        if r.returncode != 0:
            sys.exit(f"build_docs: sphinx-build failed (exit {r.returncode}): every warning is an error")

    try:
        step("doxygen (pkm.h to XML)", run_doxygen)
    except subprocess.CalledProcessError as e:
        sys.exit(f"build_docs: doxygen failed (exit {e.returncode}); its warnings are errors")
    step("sphinx-build -W", run_sphinx)
    print(f"build_docs: site in {out}/index.html, {time.monotonic() - total:.1f} s in all")


if __name__ == "__main__":
    main()
