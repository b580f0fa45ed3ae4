#!/bin/sh
# Packed bond kernel (docs/styles/fix_bond_breakable.md, "Packed kernel"):
# the same runs with two liggghts-mill builds, one run at a time, alternating
# (before, after, before, after, ...), so that both see the same machine:
#   bench/bond_kernel/lanes.sh BEFORE_EXE AFTER_EXE [ROUNDS]
#   WHAT=impact|in_mill|both (default both)
# impact:  the 4 m/s reference impact (bench/breakage/reference_impact_4ms.yaml:
#          3344 elements, the full 6 ms, one core), CPU of the impact deck;
# in_mill: the reference lump in the mill (bench/in_mill/run.sh, 20 ms, one
#          core), CPU of the whole in-mill job.
# Prints one line per run (build, round, CPU seconds) and whether each
# after-run's results are byte for byte the before-run's of its round.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
before=$1
after=$2
rounds=${3:-2}
what=${WHAT:-both}
out=${OUT:-/tmp/mill_bench_lanes}
mkdir -p "$out"
same() {  # same DIR_A DIR_B FILE...: reports files that differ
  a=$1 b=$2
  shift 2
  for f in "$@"; do
    if cmp -s "$a/$f" "$b/$f"; then :; else echo "  DIFFERS: $f"; fi
  done
}
r=1
while [ "$r" -le "$rounds" ]; do
  for build in before after; do
    exe=$before
    [ "$build" = after ] && exe=$after
    if [ "$what" != in_mill ]; then
      dir="$out/impact_${build}_$r"
      rm -rf "$dir" "$dir.time"
      MILL_LIGGGHTS="$root/bench/breakage/time_wrap.sh" TW_EXE="$exe" TW_OUT="$dir.time" \
        "$root/build/bin/orchestrate" --case "$root/bench/breakage/reference_impact_4ms.yaml" \
        --stage breakage --output "$dir" > "$dir.log" 2>&1
      awk -v b="$build" -v r="$r" '{ printf "impact  %-6s round %d: %.1f s CPU\n", b, r, $2 + $3 }' "$dir.time"
    fi
    if [ "$what" != impact ]; then
      dir="$out/in_mill_${build}_$r"
      OUT="$dir" MILL_LIGGGHTS="$exe" "$root/bench/in_mill/run.sh" > "$dir.log" 2>&1
      cpu=$(awk -F': ' '/User time/ { u = $2 } /System time/ { s = $2 } END { printf "%.1f", u + s }' "$dir/in_mill.time")
      echo "in_mill $build round $r: $cpu s CPU"
    fi
  done
  job=breakage/jobs/v4_a90_r0
  [ "$what" != in_mill ] && same "$out/impact_before_$r" "$out/impact_after_$r" \
    $job/run/final.dump $job/run/breaks.txt $job/run/ledger.csv $job/run/bonds_final.txt $job/fractions.csv
  job=breakage/jobs/rpm2000_mill_p1
  [ "$what" != impact ] && same "$out/in_mill_before_$r" "$out/in_mill_after_$r" \
    $job/run/impacts.csv $job/run/breaks.txt $job/run/ledger.csv $job/run/final.dump
  r=$((r + 1))
done
