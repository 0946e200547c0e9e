#!/bin/sh
# SPDX-License-Identifier: BSD-2-Clause
# Runs its arguments as a user who obeys file permissions: as it is for an
# ordinary user; as root, with every capability dropped (setpriv, from
# util-linux), so that a read-only directory is read-only to it too (root
# writes into one through CAP_DAC_OVERRIDE). The user stays root: the files
# root owns are still readable. Used by the read-only --out checks
# (tests/run_program.cmake, python_checks/test_command_line.py).
#   tests/without_privileges.sh PROGRAM [ARGUMENT...]
if [ "$(id -u)" != 0 ]; then exec "$@"; fi
if ! command -v setpriv >/dev/null 2>&1; then
  echo "without_privileges.sh: running as root, and setpriv (util-linux) is missing to drop root's capabilities" >&2
  exit 125
fi
exec setpriv --inh-caps=-all --bounding-set=-all -- "$@"
