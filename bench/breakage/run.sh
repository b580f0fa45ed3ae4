#!/bin/sh
# Breakage benchmarks; figures go to bench/README.md.
#   bench/breakage/run.sh [build-dir]        one reference impact, 150 m/s, 6 ms, 1 core
#   SWEEP=1 bench/breakage/run.sh [build]    the reference sweep of cases/reference.yaml, --jobs 2
#   NP=1 SWEEP=1 bench/breakage/run.sh      the same with 1 MPI rank per impact (case: 2); on a
#                                            machine with only jobs x 1 free cores this avoids
#                                            ranks spinning in MPI waits
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
build=${1:-$root/build}
out=${OUT:-/tmp/mill_bench_breakage}
mkdir -p "$out"
if [ "${SWEEP:-0}" = 1 ]; then
  /usr/bin/time -v "$build/bin/orchestrate" --case "$root/cases/reference.yaml" --stage breakage --jobs 2 \
    ${NP:+--np "$NP"} --output "$out/sweep" 2> "$out/sweep.time" | tee "$out/sweep.log"
  grep -E "Elapsed|Maximum resident|User time|System time" "$out/sweep.time"
  echo "load average after the run: $(cut -d' ' -f1-3 /proc/loadavg)"
  exit 0
fi
rm -rf "$out/impact"
/usr/bin/time -v "$build/bin/orchestrate" --case "$here/reference_impact.yaml" --stage breakage \
  --output "$out/impact" 2> "$out/impact.time" | tee "$out/impact.log"
log="$out/impact/breakage/jobs/v150_a90_r0/run/liggghts.log"
steps=$(grep -E "^Loop time" "$log" | awk '{s += $9} END {print s}')
loop=$(grep -E "^Loop time" "$log" | awk '{s += $4} END {print s}')
echo "steps $steps, loop time $loop s, element-steps/s $(echo "3344 * $steps / $loop" | bc -l)"
grep -E "Elapsed|Maximum resident|User time|System time" "$out/impact.time"
echo "load average after the run: $(cut -d' ' -f1-3 /proc/loadavg)"
