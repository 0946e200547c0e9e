# SPDX-License-Identifier: BSD-2-Clause
"""Every platform in one archive per FMU (cmake/Platforms.cmake):

- the merged archives hold the binaries of every platform and the sources,
  and fmpy validates them;
- the Windows x64 binary, run under wine through fmpy's remoting (a linux64
  client that talks over TCP to a win64 server process under wine), passes
  the auto-test through both FMUs and agrees with the linux64 binary to
  1e-12 relative (RK4; CVODE to its rtol). Its FMU states are tested under
  wine in C++ (test_fmi_lifecycle): fmpy 0.3.32's remoting client does not
  forward fmi2GetFMUstate (it answers Error);
- the source code builds with `fmpy compile` (nothing but a C++17 compiler:
  Eigen inside, RK4 only), and the compiled FMU reproduces the binary's
  auto-test; solver = 0 (CVODE) is refused with a clear message.

fmpy's remoting under Debian's wine, two catches:
its client starts `wine64`, which Debian keeps in /usr/lib/wine, not on
PATH; and it passes the server a third argument, a lock file, which the
server under wine finds open already, so it exits and the client hangs. A
`wine64` first on PATH that runs the real one with the first two arguments
only serves both.
"""
import multiprocessing
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import simulate_fmu
from fmpy.util import add_remoting

from pkm4puu.cli.autotest import BOUNDS, SOLVERS, half_step_forces, run_case

PLATFORMS = {2: {"linux64", "win64"}, 3: {"x86_64-linux", "x86_64-windows", "aarch64-linux"}}
# The Windows binary against linux64, relative to each coordinate's largest
# magnitude: RK4 to 1e-12 (the same operations; only the math library's last
# bits differ); CVODE to its own tolerance rtol, as its step-size decisions
# react to those bits (tests/test_fmi_autotest_chain.cpp says more).
PLATFORM_RTOL = {"RK4": 1e-12, "CVODE": SOLVERS["CVODE"].get("rtol", 1e-8)}
REAL_WINE64 = Path("/usr/lib/wine/wine64")


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("ident", ["PKM4PUU", "PKM4PUU_Inverse"])
def test_merged_archive_holds_every_platform_and_validates(dist_fmus, version, ident):
    fmu = dist_fmus[(version, ident)]
    with zipfile.ZipFile(fmu) as z:
        names = z.namelist()
    assert {n.split("/")[1] for n in names if n.startswith("binaries/")} == PLATFORMS[version]
    assert any(n == "sources/Eigen/Dense" for n in names), "Eigen is not inside the sources"
    if version == 3:
        assert "sources/buildDescription.xml" in names
    out = subprocess.run([sys.executable, "-m", "fmpy.cli", "validate", str(fmu)], capture_output=True, text=True)
    assert out.returncode == 0 and "No problems found" in out.stdout, out.stdout + out.stderr


@pytest.fixture(scope="module")
def wine64_shim(tmp_path_factory):
    """A directory with the `wine64` that fmpy's remoting client can start."""
    if not REAL_WINE64.is_file():
        pytest.fail(f"{REAL_WINE64} missing: ./scripts/setup.sh installs wine64", pytrace=False)
    d = tmp_path_factory.mktemp("wine64")
    shim = d / "wine64"
    shim.write_text(f'#!/bin/sh\n# fmpy remoting: server and port only (see test_fmu_platforms.py)\n'
                    f'WINEDEBUG=-all exec {REAL_WINE64} "$1" "$2"\n')
    shim.chmod(0o755)
    return d


@pytest.fixture(scope="module")
def plant_win64_remoting(dist_fmus, wine64_shim, tmp_path_factory):
    """The plant's FMI 2.0 archive with the win64 binary only, wrapped by
    fmpy's remoting for this linux64 host; wine64's shim first on PATH."""
    out = tmp_path_factory.mktemp("remoting") / "PKM4PUU.fmu"
    with zipfile.ZipFile(dist_fmus[(2, "PKM4PUU")]) as src, zipfile.ZipFile(out, "w") as dst:
        for info in src.infolist():
            if not info.filename.startswith(("binaries/linux64/", "sources/")):
                dst.writestr(info, src.read(info))
    add_remoting(str(out), "linux64", "win64")
    path = os.environ["PATH"]
    os.environ["PATH"] = f"{wine64_shim}{os.pathsep}{path}"
    yield out
    os.environ["PATH"] = path


@pytest.fixture(scope="module")
def half_step_table(inverse_fmu):
    return half_step_forces(inverse_fmu)


def _agree(a, b, rtol, what):
    """Each pose coordinate within rtol of that coordinate's largest magnitude."""
    scale = np.abs(b).max(axis=0)
    rel = np.abs(a - b).max(axis=0) / scale
    print(f"\n{what}: max relative difference per coordinate (x, y, z, phi): {rel}")
    assert np.all(rel <= rtol), f"{what}: {rel} > {rtol}"


REMOTING_TIMEOUT = 180  # s; the run itself takes about 5 s


def run_case_through_remoting(fmu, solver, table):
    """run_case in a child process with a time limit. fmpy 0.3.32's remoting
    client waits without a timeout on its server; once in a full test run it
    waited forever in fmi2FreeInstance after the server had gone. A hung
    attempt is killed and tried once more (and said so), rather than hanging
    the test command."""
    ctx = multiprocessing.get_context("fork")
    for attempt in (1, 2):
        with ctx.Pool(1) as pool:
            try:
                return pool.apply_async(run_case, (fmu, "midpoint", solver, table)).get(timeout=REMOTING_TIMEOUT)
            except multiprocessing.TimeoutError:
                print(f"\nfmpy remoting, {solver}: attempt {attempt} hung for {REMOTING_TIMEOUT} s and was killed")
    pytest.fail(f"fmpy remoting hung twice ({REMOTING_TIMEOUT} s each)")


@pytest.mark.parametrize("solver", list(SOLVERS))
def test_windows_binary_auto_test_through_remoting(plant_win64_remoting, plant_fmu, half_step_table, solver):
    win = run_case_through_remoting(plant_win64_remoting, solver, half_step_table)
    assert win.finite()
    assert win.pos_err.max() <= BOUNDS.position and win.phi_err.max() <= BOUNDS.phi
    linux = run_case(plant_fmu, "midpoint", solver, half_step_table)
    _agree(win.pose, linux.pose, PLATFORM_RTOL[solver], f"win64 (wine, remoting) vs linux64, {solver}")


def _missing_build_tools():
    """What `fmpy compile` needs and this machine lacks: CMake and a C++
    compiler (as CMake finds one: $CXX, else c++, g++ or clang++ on the PATH)."""
    missing = [] if shutil.which("cmake") else ["cmake"]
    compiler = os.environ.get("CXX") or next((c for c in ("c++", "g++", "clang++") if shutil.which(c)), None)
    if not compiler or not shutil.which(compiler.split()[0]):
        missing.append("a C++ compiler ($CXX, c++, g++ or clang++)")
    return missing


# `fmpy compile` builds the whole core (about 80 s of CPU, two compilers at
# a time): where its tools are, as wherever the project builds.
MISSING_BUILD_TOOLS = _missing_build_tools()
needs_compile = pytest.mark.skipif(bool(MISSING_BUILD_TOOLS),
                                   reason=f"fmpy compile of the source FMU needs {' and '.join(MISSING_BUILD_TOOLS)}")


@pytest.fixture(scope="module")
def compiled_plant(dist_fmus, tmp_path_factory):
    """The plant's FMI 3.0 archive with its x86_64-linux binary replaced by
    `fmpy compile` from sources/."""
    out = tmp_path_factory.mktemp("compiled") / "PKM4PUU.fmu"
    shutil.copyfile(dist_fmus[(3, "PKM4PUU")], out)
    env = {**os.environ, "CMAKE_BUILD_PARALLEL_LEVEL": "2"}
    r = subprocess.run([sys.executable, "-m", "fmpy.cli", "compile", str(out)], capture_output=True, text=True,
                       env=env)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    with zipfile.ZipFile(out) as z, zipfile.ZipFile(dist_fmus[(3, "PKM4PUU")]) as orig:
        so = "binaries/x86_64-linux/PKM4PUU.so"
        assert z.read(so) != orig.read(so), "fmpy compile left the binary as it was"
    return out


@needs_compile
def test_compiled_source_fmu_reproduces_the_auto_test(compiled_plant, plant_fmu3, half_step_table):
    built = run_case(compiled_plant, "midpoint", "RK4", half_step_table)
    assert built.pos_err.max() <= BOUNDS.position and built.phi_err.max() <= BOUNDS.phi
    binary = run_case(plant_fmu3, "midpoint", "RK4", half_step_table)
    _agree(built.pose, binary.pose, PLATFORM_RTOL["RK4"], "source build (fmpy compile) vs binary, RK4")


@needs_compile
def test_compiled_source_fmu_refuses_cvode_clearly(compiled_plant, capfd):
    """solver = 0 fails the initialisation with a message that says why
    (through the FMI logger: fmpy's default logger prints it). Logging on:
    an FMI 3.0 FMU logs nothing with logging off (3.0.2 section 2.3.1)."""
    with pytest.raises(Exception, match="fmi3ExitInitializationMode"):
        simulate_fmu(compiled_plant, start_values={"solver": 0}, stop_time=1e-3, debug_logging=True)
    out = capfd.readouterr()
    assert "solver = 0 (CVODE) is not in this build" in out.out + out.err, out
