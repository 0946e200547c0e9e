#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-2-Clause
"""Every source file of the project (C, C++, Python, shell, CMake, the
version script, pyproject.toml; not third_party/ nor hidden folders, not
generated or data files) starts with its SPDX licence line, after a shebang if it has one.

usage: check_spdx.py [--fix] [ROOT]   (ROOT: the repository, default: this script's ..)
Exit status 1 and the files listed when one lacks it; --fix adds it.
"""
import subprocess
import sys
from pathlib import Path

TAG = "SPDX-License-Identifier: BSD-2-Clause"
SLASH = ("cpp", "hpp")
BLOCK = ("c", "h", "map")  # C headers may be read by a C89 compiler; ld's version scripts take /* */ only
HASH = ("py", "sh", "cmake", "toml")
HASH_NAMES = ("CMakeLists.txt", "requirements.txt")


def comment(path):
    """The file's SPDX line, or None for a file that needs none."""
    name = path.name
    ext = name.rsplit(".", 1)[-1] if "." in name else ""
    if ext in SLASH:
        return f"// {TAG}"
    if ext in BLOCK:
        return f"/* {TAG} */"
    if ext in HASH or name in HASH_NAMES:
        return f"# {TAG}"
    return None


def project_files(root):
    out = subprocess.run(["git", "-C", str(root), "ls-files"], check=True, capture_output=True, text=True).stdout
    for rel in out.splitlines():
        if rel.startswith(("third_party/", ".")):  # vendored code; the CI's own files
            continue
        line = comment(Path(rel))
        if line and (root / rel).is_file():
            yield rel, line


def missing(root):
    bad = []
    for rel, line in project_files(root):
        lines = (root / rel).read_text(encoding="utf-8").splitlines()
        first = 1 if lines and lines[0].startswith("#!") else 0
        if len(lines) <= first or lines[first] != line:
            bad.append((rel, line))
    return bad


def main(argv):
    fix = "--fix" in argv
    rest = [a for a in argv[1:] if a != "--fix"]
    root = Path(rest[0]) if rest else Path(__file__).resolve().parent.parent
    bad = missing(root)
    if fix:
        for rel, line in bad:
            p = root / rel
            text = p.read_text(encoding="utf-8")
            if text.startswith("#!"):
                shebang, _, body = text.partition("\n")
                text = f"{shebang}\n{line}\n{body}"
            else:
                text = f"{line}\n{text}"
            p.write_text(text, encoding="utf-8")
        bad = missing(root)
    for rel, line in bad:
        print(f"{rel}: first line (after a shebang) is not '{line}'")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
