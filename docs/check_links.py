#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-2-Clause
"""README.md is a front page of at most 250 lines, and every relative link of
README.md and docs/*.md resolves: the file exists and, for `file#anchor`
(or `#anchor`), the file has a heading with that anchor (GitHub's and
MyST's slug: lower case, punctuation dropped, spaces to hyphens) or an
explicit MyST target `(anchor)=`.

usage: check_links.py [ROOT]   (the repository; default: this script's ..)
Exit status 1 with every broken link listed.
"""
import re
import sys
from pathlib import Path

MAX_README_LINES = 250
LINK = re.compile(r"!?\[(?:[^\]\\]|\\.)*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
FENCE = re.compile(r"^(```|~~~)")


def slug(heading):
    """GitHub's anchor of a heading, which MyST's myst_heading_anchors follows."""
    text = re.sub(r"`([^`]*)`", r"\1", heading.strip()).lower()
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def prose_lines(path):
    """The lines outside fenced code blocks, numbered from 1."""
    fenced = False
    for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        if FENCE.match(line.lstrip()):
            # a MyST directive ({toctree}, {literalinclude}) is no code: its links are checked by Sphinx
            fenced = not fenced
            continue
        if not fenced:
            yield n, line


def anchors(path):
    found = set()
    for _, line in prose_lines(path):
        m = re.match(r"^#{1,6}\s+(.*?)\s*#*\s*$", line)
        if m:
            found.add(slug(m.group(1)))
        m = re.match(r"^\(([^)]+)\)=\s*$", line)
        if m:
            found.add(m.group(1))
    return found


def check(root):
    errors = []
    readme = root / "README.md"
    n = len(readme.read_text(encoding="utf-8").splitlines())
    if n > MAX_README_LINES:
        errors.append(f"README.md has {n} lines, more than {MAX_README_LINES}")
    files = [readme] + sorted((root / "docs").glob("*.md"))
    cache = {}
    checked = 0
    for path in files:
        for n, line in prose_lines(path):
            for target in LINK.findall(line):
                if re.match(r"^[a-z][a-z0-9+.-]*:", target):  # http:, https:, mailto:
                    continue
                checked += 1
                file_part, _, anchor = target.partition("#")
                dest = (path.parent / file_part).resolve() if file_part else path
                where = f"{path.relative_to(root)}:{n}: {target}"
                if not dest.exists():
                    errors.append(f"{where}: no such file")
                    continue
                if anchor:
                    if dest.suffix != ".md":
                        errors.append(f"{where}: an anchor into a file that is not Markdown")
                        continue
                    if dest not in cache:
                        cache[dest] = anchors(dest)
                    if anchor not in cache[dest]:
                        errors.append(f"{where}: no heading or target '{anchor}' in {dest.name}")
    return errors, checked, len(files)


def main():
    root = Path(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).resolve().parents[1]).resolve()
    errors, checked, nfiles = check(root)
    for e in errors:
        print(e)
    print(f"check_links: {checked} relative links in {nfiles} files, {len(errors)} problem(s)")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
