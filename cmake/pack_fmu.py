# SPDX-License-Identifier: BSD-2-Clause
"""Writes an FMU archive (zip) that depends only on the files' contents:
entries in the order given, each dated the stamp's epoch (the commit's date
or $SOURCE_DATE_EPOCH: cmake/source_stamp.cmake; 1980-01-01 without a
stamp), permissions 0644 (0755 for binaries), no extra fields (no atime,
ctime, uid or gid), deflated. The same commit therefore builds
bit-identical archives.

The archive's modelDescription.xml is the committed one stamped with what
changes from commit to commit, which the committed file cannot hold:
generationTool gets " (commit COMMIT)" appended and generationDateAndTime is
added, the stamp's epoch, so the stamp is reproducible.

usage: pack_fmu.py [--stamp STAMP.json] OUTPUT STAGE_DIR FILE...   (FILEs relative to STAGE_DIR)
"""
import json
import os
import re
import sys
import time
import zipfile


def stamp(xml, commit, epoch):
    """modelDescription.xml's text with the commit in generationTool and
    generationDateAndTime after it (unchanged if it has the latter)."""
    if "generationDateAndTime=" in xml:
        return xml
    m = re.search(r'\n([ \t]*)generationTool="([^"]*)"', xml)
    if not m:
        sys.exit("pack_fmu: modelDescription.xml has no generationTool attribute on a line of its own")
    indent, tool = m.group(1), m.group(2) + (f" (commit {commit})" if commit else "")
    date = time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime(epoch))
    return (xml[:m.start()] + f'\n{indent}generationTool="{tool}"\n{indent}generationDateAndTime="{date}"' +
            xml[m.end():])


EARLIEST = 315532800  # 1980-01-01, zip's earliest date


def read_stamp(path):
    """(epoch, commit) from the build's source stamp (cmake/source_stamp.cmake);
    1980-01-01 and no commit without one."""
    if not path:
        return EARLIEST, ""
    with open(path, encoding="utf-8") as f:
        data = json.load(f)
    return max(int(data["epoch"]), EARLIEST), data["commit"]


def main(argv):
    stamp_file = None
    if len(argv) > 2 and argv[1] == "--stamp":
        stamp_file, argv = argv[2], argv[:1] + argv[3:]
    if len(argv) < 4:
        sys.exit(__doc__)
    out, stage, files = argv[1], argv[2], argv[3:]
    epoch, commit = read_stamp(stamp_file)
    date_time = time.gmtime(epoch)[:6]
    tmp = out + ".tmp"
    with zipfile.ZipFile(tmp, "w") as z:
        for name in files:
            with open(os.path.join(stage, name), "rb") as f:
                data = f.read()
            if name == "modelDescription.xml":
                data = stamp(data.decode("utf-8"), commit, epoch).encode("utf-8")
            info = zipfile.ZipInfo(name, date_time=date_time)
            info.compress_type = zipfile.ZIP_DEFLATED
            info.create_system = 3  # Unix, so that the permissions below mean something
            mode = 0o755 if name.startswith("binaries/") else 0o644
            info.external_attr = (0o100000 | mode) << 16
            z.writestr(info, data, compresslevel=9)
    os.replace(tmp, out)


if __name__ == "__main__":
    main(sys.argv)
