# SPDX-License-Identifier: BSD-2-Clause
"""Writes an FMU archive (zip) that depends only on the files' contents:
entries in the order given, each dated SOURCE_DATE_EPOCH (the commit's date
when the build passes it; 1980-01-01 otherwise), permissions 0644 (0755 for
binaries), no extra fields (no atime, ctime, uid or gid), deflated.
The same commit therefore builds bit-identical archives.

usage: pack_fmu.py OUTPUT STAGE_DIR FILE...   (FILEs relative to STAGE_DIR)
"""
import os
import sys
import time
import zipfile


def main(argv):
    if len(argv) < 4:
        sys.exit(__doc__)
    out, stage, files = argv[1], argv[2], argv[3:]
    epoch = int(os.environ.get("SOURCE_DATE_EPOCH", "315532800"))  # 1980-01-01, zip's earliest date
    date_time = time.gmtime(max(epoch, 315532800))[:6]
    tmp = out + ".tmp"
    with zipfile.ZipFile(tmp, "w") as z:
        for name in files:
            with open(os.path.join(stage, name), "rb") as f:
                data = f.read()
            info = zipfile.ZipInfo(name, date_time=date_time)
            info.compress_type = zipfile.ZIP_DEFLATED
            info.create_system = 3  # Unix, so that the permissions below mean something
            mode = 0o755 if name.startswith("binaries/") else 0o644
            info.external_attr = (0o100000 | mode) << 16
            z.writestr(info, data, compresslevel=9)
    os.replace(tmp, out)


if __name__ == "__main__":
    main(sys.argv)
