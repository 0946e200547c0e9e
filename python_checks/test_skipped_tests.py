# SPDX-License-Identifier: BSD-2-Clause
"""The test command's summary of skipped tests (scripts/skipped_tests.py),
fed with the JUnit XML that ctest and pytest write for a small suite of each
with skips of every kind the project uses: ctest's SKIP_RETURN_CODE and
SKIP_REGULAR_EXPRESSION (googletest's "Skipped" among them), pytest's
skipif and skip(); and googletest's own XML. Each skip is counted and shown
with its reason; a part that did not run is named."""
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[1] / "scripts" / "skipped_tests.py"

CTEST_PROJECT = r"""cmake_minimum_required(VERSION 3.21)
project(skips NONE)
enable_testing()
add_test(NAME runs COMMAND ${CMAKE_COMMAND} -E echo fine)
add_test(NAME exit_77 COMMAND sh -c "echo 'clang not found: setup.sh installs it' >&2; exit 77")
set_tests_properties(exit_77 PROPERTIES SKIP_RETURN_CODE 77)
add_test(NAME says_so COMMAND ${CMAKE_COMMAND} -E echo "valgrind not found (Debian: valgrind)")
set_tests_properties(says_so PROPERTIES SKIP_REGULAR_EXPRESSION "valgrind not found")
add_test(NAME gtest_skip COMMAND sh -c "printf '[ RUN      ] Suite.Case\nx.cpp:59: Skipped\nnm not available\n\n[  SKIPPED ] Suite.Case (0 ms)\n'")
set_tests_properties(gtest_skip PROPERTIES SKIP_REGULAR_EXPRESSION "\\[  SKIPPED \\]")
"""

PYTEST_FILE = '''import pytest


def test_runs():
    pass


@pytest.mark.skipif(True, reason="fmi-sim is not installed")
@pytest.mark.parametrize("k", range(6))
def test_needs_fmi_sim(k):
    pass


def test_needs_cmake():
    pytest.skip("cmake not found")
'''

# googletest's XML (GTEST_OUTPUT=xml:DIR/) for one test run and one skipped.
GTEST_XML = """<?xml version="1.0" encoding="UTF-8"?>
<testsuites tests="2" failures="0" disabled="0" errors="0" time="0.1" name="AllTests">
  <testsuite name="FmuBinaries" tests="2" failures="0" disabled="0" skipped="1" errors="0" time="0.1">
    <testcase name="Load" status="run" result="completed" time="0" classname="FmuBinaries" />
    <testcase name="Exports" status="run" result="skipped" time="0" classname="FmuBinaries">
      <skipped message="../tests/fmi/binary.cpp:59&#x0A;objdump not available&#x0A;"><![CDATA[../tests/fmi/binary.cpp:59
objdump not available
]]></skipped>
    </testcase>
  </testsuite>
</testsuites>
"""


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    d = tmp_path_factory.mktemp("skips")
    project = d / "project"
    project.mkdir()
    (project / "CMakeLists.txt").write_text(CTEST_PROJECT)
    subprocess.run(["cmake", "-S", project, "-B", project / "build"], check=True, capture_output=True)
    subprocess.run(["ctest", "--test-dir", project / "build", "--output-junit", d / "ctest.xml"], check=True,
                   capture_output=True)
    (d / "test_sample.py").write_text(PYTEST_FILE)
    subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", f"--rootdir={d}",
                    f"--junitxml={d / 'pytest.xml'}", d / "test_sample.py"], check=True, capture_output=True, cwd=d)
    (d / "gtest").mkdir()
    (d / "gtest" / "fmi_binary.xml").write_text(GTEST_XML)
    return d


def summary(*suites):
    proc = subprocess.run([sys.executable, SCRIPT, *suites], capture_output=True, text=True)
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr
    return proc.stdout.splitlines()


@pytest.mark.skipif(not (shutil.which("cmake") and shutil.which("ctest")), reason="cmake and ctest not found")
def test_every_skip_is_counted_with_its_reason(results):
    lines = summary(f"ctest={results / 'ctest.xml'}", f"pytest={results / 'pytest.xml'}",
                    f"gtest={results / 'gtest'}")
    assert lines[0] == "skipped tests: 11 (ctest 3 of 4, pytest 7 of 8, gtest 1 of 2)", lines
    text = "\n".join(lines)
    for suite, n, reason in [("ctest", 1, "clang not found: setup.sh installs it"),
                             ("ctest", 1, "valgrind not found (Debian: valgrind)"),
                             ("ctest", 1, "nm not available"),
                             ("pytest", 6, "fmi-sim is not installed"),
                             ("pytest", 1, "cmake not found"),
                             ("gtest", 1, "objdump not available")]:
        assert f"  {suite}, {n} skipped: {reason}\n" in text + "\n", text
    # Each reason's tests, the first four by name.
    assert "    test_sample.test_needs_fmi_sim[0], test_sample.test_needs_fmi_sim[1], " \
           "test_sample.test_needs_fmi_sim[2], test_sample.test_needs_fmi_sim[3] and 2 more" in lines
    assert "    FmuBinaries.Exports" in lines and "    gtest_skip" in lines
    assert "runs" not in text and "Load" not in text


def test_a_part_that_did_not_run_is_named(tmp_path):
    lines = summary(f"pytest sanitized={tmp_path / 'pytest_sanitized.xml'}")
    assert lines == ["skipped tests: 0 (no results)",
                     f"  pytest sanitized: no results ({tmp_path / 'pytest_sanitized.xml'} missing: it did not run)"]


@pytest.mark.parametrize("argument", ["ctest", "=x.xml", "ctest="])
def test_a_bad_argument_is_refused(argument):
    proc = subprocess.run([sys.executable, SCRIPT, argument], capture_output=True, text=True)
    assert proc.returncode == 2 and proc.stdout == ""
    assert proc.stderr == f"skipped_tests.py: '{argument}' is not NAME=PATH (usage: skipped_tests.py NAME=PATH...)\n"
