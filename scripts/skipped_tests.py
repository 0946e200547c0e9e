#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-2-Clause
"""The tests a run skipped, and why: the end of the test command's output,
so that a check left out for a missing tool shows there instead of passing
in silence.

usage: skipped_tests.py NAME=PATH...

Each PATH is a JUnit XML file, or a folder of them, as ctest
(--output-junit), pytest (--junitxml) and googletest (GTEST_OUTPUT=xml:DIR/)
write them; NAME labels its tests in the summary. Prints how many tests of
each ran and were skipped, then each reason once with the tests it
skipped. A PATH that does not exist is reported (that part did not run),
not an error. Exit status 0 (a summary, not a verdict); 2 for a usage error.
"""
import re
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

SHOWN = 4  # the tests named per reason; the rest are counted
LOCATION = re.compile(r"^\S+:\d+$")  # googletest's first line of a skip message


def _ctest_reason(output):
    """A ctest test's own words for its skip: googletest's message (the
    lines after "<file>:<line>: Skipped"), else the output's last line."""
    lines = [line.strip() for line in output.splitlines()]
    for k, line in enumerate(lines):
        if line.endswith(": Skipped"):
            said = []
            for text in lines[k + 1:]:
                if not text or text.startswith("[  SKIPPED ]"):
                    break
                said.append(text)
            return " ".join(said) or "GTEST_SKIP() without a message"
    said = [line for line in lines if line]
    return said[-1] if said else ""


def skipped_cases(path):
    """(number of tests, [(test, reason)] of the skipped ones) of one JUnit
    XML file."""
    cases = ET.parse(path).getroot().iter("testcase")
    total, skipped = 0, []
    for case in cases:
        total += 1
        mark = case.find("skipped")
        if mark is None and case.get("status") not in ("notrun", "disabled"):
            continue
        name, group = case.get("name", "?"), case.get("classname", "")
        if group and group != name:  # pytest: the module (python_checks.test_x); googletest: the suite
            name = f"{group}.{name}"
        message = mark.get("message", "") if mark is not None else ""
        out = case.find("system-out")
        if message.startswith("SKIP_") and out is not None:  # ctest: SKIP_RETURN_CODE=77, SKIP_REGULAR_EXPRESSION_MATCHED
            reason = _ctest_reason(out.text or "")
        else:  # pytest's reason; googletest's "<file>:<line>" and message
            reason = " ".join(line for line in message.splitlines() if not LOCATION.match(line))
        skipped.append((name, (reason or message or case.get("status", "skipped")).strip()))
    return total, skipped


def summary(suites):
    """The summary's lines for [(name, path)]."""
    counts, reasons, missing = [], {}, []
    for name, path in suites:
        files = sorted(path.glob("*.xml")) if path.is_dir() else [path] if path.is_file() else []
        if not files:
            missing.append(f"{name}: no results ({path} missing: it did not run)")
            continue
        total = 0
        for f in files:
            n, skipped = skipped_cases(f)
            total += n
            for test, reason in skipped:
                reasons.setdefault((name, reason), []).append(test)
        n_skipped = sum(len(tests) for (suite, _), tests in reasons.items() if suite == name)
        counts.append(f"{name} {n_skipped} of {total}")
    n = sum(len(tests) for tests in reasons.values())
    lines = [f"skipped tests: {n} ({', '.join(counts) or 'no results'})"]
    for (name, reason), tests in reasons.items():
        shown = ", ".join(tests[:SHOWN]) + (f" and {len(tests) - SHOWN} more" if len(tests) > SHOWN else "")
        lines.append(f"  {name}, {len(tests)} skipped: {reason}")
        lines.append(f"    {shown}")
    lines += [f"  {text}" for text in missing]
    return lines


def main(argv):
    usage = "usage: skipped_tests.py NAME=PATH..."
    suites = [arg.partition("=") for arg in argv]
    bad = [arg for arg, (name, sep, path) in zip(argv, suites) if not (name and sep and path)]
    if not argv or bad:
        print(f"skipped_tests.py: '{bad[0]}' is not NAME=PATH ({usage})" if bad else usage, file=sys.stderr)
        return 2
    print("\n".join(summary([(name, Path(path)) for name, _, path in suites])))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
