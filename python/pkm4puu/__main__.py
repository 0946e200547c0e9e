# SPDX-License-Identifier: BSD-2-Clause
"""python -m pkm4puu COMMAND [ARGS...]: the pkm4puu command (pkm4puu.cli)."""
import sys

from .cli import main

if __name__ == "__main__":
    sys.exit(main())
