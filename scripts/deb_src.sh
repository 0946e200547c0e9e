#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-2-Clause
# deb-src entries for the mirrors apt already uses.
#   scripts/deb_src.sh           prints deb822 stanzas (Types: deb-src) made from
#                                every deb entry: same URIs, Suites, Components, Signed-By
#   scripts/deb_src.sh --check   exit 0 when apt already has an enabled deb-src entry
# Reads /etc/apt/sources.list and /etc/apt/sources.list.d/*.{list,sources}.
set -euo pipefail
shopt -s nullglob
lists=(/etc/apt/sources.list /etc/apt/sources.list.d/*.list)
deb822=(/etc/apt/sources.list.d/*.sources)

if [ "${1:-}" = "--check" ]; then
  for f in "${lists[@]}"; do
    [ -f "$f" ] && grep -Eq '^[[:space:]]*deb-src[[:space:]]' "$f" && exit 0
  done
  for f in "${deb822[@]}"; do
    grep -Eiq '^Types:.*\bdeb-src\b' "$f" && ! grep -Eiq '^Enabled:[[:space:]]*no' "$f" && exit 0
  done
  exit 1
fi

for f in "${deb822[@]}"; do
  # One stanza per blank-line-separated block whose Types include deb.
  awk 'function flush() {
         if (types ~ /(^|[ \t])deb([ \t]|$)/ && enabled !~ /no/ && uris != "")
           printf "Types: deb-src\nURIs:%s\nSuites:%s\nComponents:%s\n%s\n", uris, suites, comps,
                  signed == "" ? "" : "Signed-By:" signed "\n"
         types = uris = suites = comps = signed = enabled = ""
       }
       /^[ \t]*#/ { next }
       /^[ \t]*$/ { flush(); next }
       { key = tolower($0); sub(/:.*/, "", key); val = $0; sub(/^[^:]*:/, "", val) }
       key == "types" { types = val } key == "uris" { uris = val } key == "suites" { suites = val }
       key == "components" { comps = val } key == "signed-by" { signed = val } key == "enabled" { enabled = val }
       END { flush() }' "$f"
done
for f in "${lists[@]}"; do
  [ -f "$f" ] || continue
  # deb [options] uri suite components...
  awk '$1 == "deb" {
         i = 2; opts = ""
         if ($2 ~ /^\[/) { while (i <= NF) { opts = opts " " $i; if ($(i++) ~ /\]$/) break } }
         comps = ""; for (j = i + 2; j <= NF; j++) comps = comps " " $j
         printf "Types: deb-src\nURIs: %s\nSuites: %s\nComponents:%s\n", $i, $(i + 1), comps
         if (match(opts, /signed-by=[^] ]+/)) printf "Signed-By: %s\n", substr(opts, RSTART + 10, RLENGTH - 10)
         printf "\n"
       }' "$f"
done
