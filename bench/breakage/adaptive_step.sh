#!/bin/sh
# The adaptive time step against the fixed one (issue 30; bench/README.md,
# "Adaptive time step"): the reference lump (3344 elements, 40 mm,
# cases/reference.yaml's sizes) at each speed of $SPEEDS, $REPEATS repeats
# (random orientations), the default early stop, one core, once with
# breakage.adaptive_step false and once true. Prints per run the steps, the
# liggghts-mill CPU seconds (user + sys, /usr/bin/time), pieces, largest
# piece and broken bonds, then the load average.
#   bench/breakage/adaptive_step.sh [build-dir]
#   SPEEDS="20 100" REPEATS=3 bench/breakage/adaptive_step.sh
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
build=${1:-$root/build}
out=${OUT:-/tmp/mill_bench_adaptive}
speeds=${SPEEDS:-"20 100"}
repeats=${REPEATS:-3}
mkdir -p "$out"
vlist=$(echo "$speeds" | sed 's/ /, /g')
for mode in fixed adaptive; do
  flag=false
  [ "$mode" = adaptive ] && flag=true
  cat > "$out/$mode.yaml" <<YAML
name: bench_adaptive_$mode
ore: {card: sandstone}
lump: {n_elements: 3344, diameter: 0.04}
breakage:
  velocities: [$vlist]
  angles: [90]
  repeats: $repeats
  duration_after_contact: 6.0e-3
  dump_interval: 0
  adaptive_step: $flag
resources: {np: 1, jobs: 1}
YAML
  rm -f "$out/$mode.times"
  # The lumps are the same for both modes: built once (lump jobs are keyed by their inputs).
  if [ "$mode" = adaptive ] && [ -d "$out/fixed/breakage/lumps" ] && [ ! -d "$out/adaptive/breakage/lumps" ]; then
    mkdir -p "$out/adaptive/breakage" && cp -r "$out/fixed/breakage/lumps" "$out/adaptive/breakage/"
  fi
  echo "load average before ($mode): $(cut -d' ' -f1-3 /proc/loadavg)"
  MILL_LIGGGHTS="$here/time_wrap.sh" TW_EXE="$build/bin/liggghts-mill" TW_OUT="$out/$mode.times" \
    "$build/bin/orchestrate" --case "$out/$mode.yaml" --stage breakage --jobs 1 --np 1 \
    --output "$out/$mode" > "$out/$mode.log" 2>&1
  echo "load average after ($mode): $(cut -d' ' -f1-3 /proc/loadavg)"
done
/usr/bin/python3 "$here/adaptive_summary.py" "$out"
