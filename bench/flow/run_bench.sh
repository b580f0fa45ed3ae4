#!/bin/sh
# Run one flow benchmark (quick | quick_compressible | reference) through the
# flow and sample stages and print the figures that go into bench/README.md.
# Usage: bench/flow/run_bench.sh quick [np]    (from the project root, after a build)
set -e
name=${1:-quick}
np=${2:-2}
root=$(cd "$(dirname "$0")/../.." && pwd)
exe=${ORCHESTRATE:-$root/build/bin/orchestrate}
out=${OUT:-$root/runs/bench_flow_$name}
"$exe" --case "$root/bench/flow/$name.yaml" --stage flow --np "$np" --output "$out" --force
"$exe" --case "$root/bench/flow/$name.yaml" --stage sample --output "$out" --force
/usr/bin/python3 "$root/bench/flow/summarize.py" "$out"
