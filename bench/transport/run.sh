#!/bin/bash
# Transport benchmark: flow -> sample -> transport on bench/transport/quick.yaml
# (360 lumps), each stage timed with /usr/bin/time. Usage:
#   bench/transport/run.sh [build dir] [output dir]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
build=${1:-build}
out=${2:-runs/bench_transport}
for stage in flow sample transport; do
  /usr/bin/time -f "$stage: wall %e s, user %U s, max RSS %M kB" \
    "$build/bin/orchestrate" --case "$here/quick.yaml" --stage "$stage" --output "$out" 2>&1 | tail -n 4
done
echo "results: $out/transport/rpm2000/{summary.json, impacts.csv, transport.h5, plots/}"
