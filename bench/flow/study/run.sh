#!/bin/bash
# One point of the flow study: flow (resources.np = 1 rank) -> sample -> transport (360
# lumps) on bench/flow/study/base.yaml with the given mesh preset, frozen-rotor
# angle and gas model, each stage timed. Then summarize.py prints the table.
#   bench/flow/study/run.sh quick 0 [incompressible|compressible]   (from the project root, after a build)
#   bench/flow/study/run.sh medium 0
#   bench/flow/study/run.sh reference 0
#   bench/flow/study/summarize.py runs/flow_study_*
set -euo pipefail
preset=${1:?mesh preset}
angle=${2:-0}
gas=${3:-compressible}
root=$(cd "$(dirname "$0")/../../.." && pwd)
exe=${ORCHESTRATE:-$root/build/bin/orchestrate}
out=${OUT:-$root/runs/flow_study_${preset}_a${angle}_${gas}}
mkdir -p "$out"
case_file="$out/case.yaml"
sed -e "s/^  mesh_preset: quick/  mesh_preset: $preset\n  rotor_angle: $angle/" \
    -e "s/^gas:/gas:\n  model: $gas/" \
    -e "s#card: liggghts_inputs#card: $root/liggghts_inputs#" \
    -e "s/^name: flow_study/name: flow_study_${preset}_a${angle}_${gas}/" \
    "$root/bench/flow/study/base.yaml" > "$case_file"
for stage in flow sample transport; do
  np=1
  [ "$stage" = flow ] && np=${NP:-1}   # NP=2 bench/flow/study/run.sh reference 0: the CFD on 2 ranks
  /usr/bin/time -f "$stage: wall %e s, user %U s, max RSS %M kB" \
    "$exe" --case "$case_file" --stage "$stage" --np "$np" --output "$out" 2>&1 | tail -n 3
done
echo "results: $out/{flow,sample,transport}/rpm2000"
