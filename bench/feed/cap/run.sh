#!/bin/sh
# A class lump at the element cap (issue 29; bench/README.md, "A class lump
# at the element cap"). Two cases that differ only in feed.class_element_cap:
# one 45-63 mm feed class (53 mm lumps) through the default mill at 1500 rpm
# with 8 in-mill lumps, the case's lump 20 mm of 156 elements (the default
# lump's element size); capped (feed.class_element_cap 8): the class lump
# gets 8 x 156 = 1248 elements (1.53 x the calibration's element size),
# uncapped (no cap, the default): its 5134. The two share
# the calibration (the same key), the flow and the transport (the same
# strikes), so what differs is the class lump's resolution. Prints the
# class's measured breakage column, the product and the decision of each,
# with the bootstrap bands over the 8 lumps.
#   bench/feed/cap/run.sh [build-dir]      OUT=/tmp/cap (default) for the runs
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../../.." && pwd)
build=${1:-$root/build}
out=${OUT:-/tmp/mill_bench_cap}
mkdir -p "$out"
for c in capped uncapped; do
  start=$(date +%s)
  "$build/bin/orchestrate" --case "$here/cap_$c.yaml" --stage all --output "$out/$c" > "$out/$c.log" 2>&1 ||
    { echo "run.sh: cap_$c failed, see $out/$c.log" >&2; exit 1; }
  echo "cap_$c: $(( $(date +%s) - start )) s wall"
done
/usr/bin/python3 "$here/compare.py" "$out/capped" "$out/uncapped"
