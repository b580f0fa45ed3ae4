#!/bin/sh
# The runaway element of a high-speed impact, traced step by step (bench/README.md,
# "Energy ledger"): the 3344-element reference lump at 150 m/s with the
# reference calibration's bonds, once with LIGGGHTS's two-sided primitive
# plane (the impact surface before the fix) and once with the deck as it is
# (fix wall/halfspace). Prints the fastest elements and the ledger's last row.
#   bench/breakage/runaway/trace.sh [build-dir]        (about 2.5 min on one core)
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../../.." && pwd)
build=${1:-$root/build}
out=${OUT:-/tmp/mill_bench_runaway}
mkdir -p "$out"
# The lump (built once by the orchestrator, cached in $out/lump).
"$build/bin/orchestrate" --case "$root/cases/reference.yaml" --np 1 impact --velocity 150 \
  --output "$out/lump" > "$out/lump.log"
lump=$(ls "$out"/lump/breakage/lumps/jobs/*/lump.data | head -1)
deck="$root/liggghts_inputs/impact.in.tmpl"
# The old surface: LIGGGHTS's primitive plane in place of wall/halfspace (and
# no ledger terms of the wall), plus a per-step dump of element 1324.
sed -e 's|^fix wall all wall/halfspace zplane ${z_plane}.*|fix wall all wall/gran model hertz tangential history primitive type 2 zplane ${z_plane}|' \
    -e '/^    wall_youngs ${E_wall} wall_poisson/d' -e 's| wall wall speed_bound| speed_bound|' \
    -e 's|^fix integr all nve/sphere|fix integr all nve/sphere\ngroup trace id 1324\ndump tr trace custom 1 trace.dump id radius x y z vx vy vz fx fy fz f_bonds|' \
    "$deck" > "$out/old_surface.in"
run() {  # run NAME DECK: the calibrated bonds, 150 m/s, the full 6 ms
  mkdir -p "$out/$1" && cd "$out/$1"
  "$build/bin/liggghts-mill" -in "$2" -log liggghts.log -echo none -screen none \
    -var deck_dir "$root/liggghts_inputs" -var lump_file "$lump" -var velocity 150 -var angle 90 \
    -var z_plane -0.0203516 -var t_end 6.5e-3 -var t_contact 6.77e-7 -var quiet_time 0 -var dt 0 \
    -var dt_speed 5.08e-7 -var skin 3.048e-4 -var binsize 4.064e-3 \
    -var rot_x 0.3 -var rot_y 0.5 -var rot_z 0.8 -var rot_angle 37 \
    -var bond_modulus 99.3e9 -var stiffness_ratio 3.92 -var bond_tensile 24.5e6 \
    -var bond_cohesion 49.0e6 -var bond_friction 60 -var moment_factor 0 -var bond_gap 0.15 \
    -var max_bonds 16 -var speed_bound 1e6 -var residual_bound 0 || true
  /usr/bin/python3 - <<PY
import numpy as np
d = np.loadtxt("final.dump", skiprows=9)
v = np.linalg.norm(d[:, 7:10], axis=1)
i = np.argsort(v)[-3:]
print("$1: fastest elements (id, z m, speed m/s):", [(int(d[k, 0]), round(d[k, 6], 3), round(v[k], 1)) for k in i])
print("$1: elements behind the surface:", int((d[:, 6] < -0.0203516).sum()))
PY
  tail -1 ledger.csv
}
run old_surface "$out/old_surface.in"
run halfspace "$deck"
