#!/bin/sh
# In-mill breakage benchmark; figures go to bench/README.md.
#   bench/in_mill/run.sh [build-dir]
#   DURATION=0.005 bench/in_mill/run.sh      a shorter run (s) for comparing settings
#   LEAD_TIME=5e-5 DURATION=2.5e-4 ...        a run that starts closer to the strike (s)
#   ADAPTIVE=1 DURATION=0.005 bench/in_mill/run.sh   with breakage.adaptive_step: true
#   NP=2 bench/in_mill/run.sh                 the engine run on 2 MPI ranks
#   CLOSED_FORM=1 bench/in_mill/run.sh        the closed-form bonds (no calibration written)
# The reference lump (3344 elements, the reference calibration's bonds) in the
# reference mill at 2000 rpm for 20 ms on one core: stage 1's impact record is
# one strike written here (the lump falling at 10 m/s onto plate 0's leading
# face 0.4 m from the axis, the plate pointing up at t = (pi/2)/omega), the
# calibration is the reference fit of bench/README.md ("Calibration"). Only
# the in-mill job runs (--task 1; task 0 is the single impact of the same
# strike). Prints CPU, wall, peak memory and element-steps per CPU second.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
build=${1:-$root/build}
out=${OUT:-/tmp/mill_bench_in_mill}
rm -rf "$out"
mkdir -p "$out/transport/rpm2000" "$out/calibrate"
# The key a calibration must carry for this card and lump (orchestrate --check).
key=$("$build/bin/orchestrate" --case "$here/reference_in_mill.yaml" --check |
  sed -n 's/^calibration key.*input_hash \([0-9a-f]*\).*/\1/p')
[ -n "$key" ] || { echo "run.sh: no calibration key from orchestrate --check" >&2; exit 1; }
/usr/bin/python3 - "$out" "$key" <<'PY'
import math, sys
out, key = sys.argv[1], sys.argv[2]
w = 2000 * 2 * math.pi / 60
t = 0.5 * math.pi / w
x, c, v = (-0.0305, 1.6, 0.0), (-0.01, 1.6, 0.0), (0.0, -10.0, 0.0)
rx, ry = c[0], c[1] - 1.2
vr = (v[0] + w * ry, v[1] - w * rx, v[2])
speed = math.sqrt(sum(q * q for q in vr))
vn = vr[0]  # the leading face's normal is -x; the lump approaches it along +x relative to the plate
head = ("time_s,particle_id,surface,x_m,y_m,z_m,contact_x_m,contact_y_m,contact_z_m,normal_x,normal_y,normal_z,"
        "vrel_x_m_s,vrel_y_m_s,vrel_z_m_s,speed_m_s,normal_speed_m_s,tangential_speed_m_s,angle_deg,"
        "surface_speed_m_s,particle_speed_m_s,axis_distance_m\n")
row = [t, 1, "flywheel", *x, *c, -1, 0, 0, *vr, speed, vn, math.sqrt(max(0, speed**2 - vn**2)),
       math.degrees(math.asin(vn / speed)), w * math.hypot(rx, ry), 10.0, math.hypot(rx, ry)]
open(f"{out}/transport/rpm2000/impacts.csv", "w").write(head + ",".join(str(r) for r in row) + "\n")
# The reference calibration (bench/README.md, "Calibration"), fitted to this
# card and lump (its key from orchestrate --check).
open(f"{out}/calibrate/calibrated.yaml", "w").write(
    "calibrated:\n  bond_modulus: 99.3e9\n  stiffness_ratio: 3.92\n  bond_tensile_strength: 24.5e6\n"
    "  bond_cohesion: 49.0e6\n  bond_friction_angle: 60\n  bond_moment_factor: 0\n"
    f"  input_hash: {key}\n")
PY
[ "${CLOSED_FORM:-0}" = 1 ] && rm -f "$out/calibrate/calibrated.yaml"
case_file="$here/reference_in_mill.yaml"
if [ -n "${DURATION:-}${LEAD_TIME:-}${ADAPTIVE:-}" ]; then
  sed -e "s/duration: 0.02,/duration: ${DURATION:-0.02},/" \
      -e "s/lead_time: 2.0e-3,/lead_time: ${LEAD_TIME:-2.0e-3},/" "$case_file" > "$out.case.yaml"
  [ "${ADAPTIVE:-0}" = 1 ] && sed -i -e "s/^  repeats: 1$/  repeats: 1\n  adaptive_step: true/" "$out.case.yaml"
  case_file="$out.case.yaml"
fi
/usr/bin/time -v "$build/bin/orchestrate" --case "$case_file" --stage breakage --task 1 \
  --np "${NP:-1}" --output "$out" 2> "$out/in_mill.time" | tee "$out/in_mill.log"
job="$out/breakage/jobs/rpm2000_mill_p1"
[ "${CLOSED_FORM:-0}" = 1 ] ||
  grep -q '"bond_parameters_origin": "calibrated' "$job/result.json" || echo "WARNING: the bonds were not the calibrated ones"
log="$job/run/liggghts.log"
steps=$(grep -E "^Loop time" "$log" | awk '{s += $9} END {print s}')
loop=$(grep -E "^Loop time" "$log" | awk '{s += $4} END {print s}')
cpu=$(grep -E "User time|System time" "$out/in_mill.time" | awk -F: '{s += $2} END {print s}')
echo "steps $steps, loop time $loop s, element-steps per CPU second $(echo "3344 * $steps / $cpu" | bc -l)"
grep -E "in_mill: dt|in_mill: adaptive|bins grow|Neighbor list builds|Dangerous" "$log" | head -20
[ -f "$job/run/steps.csv" ] && echo "steps.csv (step, time, dt, bonds' step, intact bonds):" && sed -n '3~4p' "$job/run/steps.csv"
grep -E "Elapsed|Maximum resident|User time|System time" "$out/in_mill.time"
echo "load average after the run: $(cut -d' ' -f1-3 /proc/loadavg)"
