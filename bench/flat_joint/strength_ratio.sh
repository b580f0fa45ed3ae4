#!/bin/sh
# Side by side: the UCS and Brazilian tests of the calibrate stage
# (liggghts_inputs/ucs.in.tmpl, brazilian.in.tmpl) on one specimen with one
# set of bond parameters, once with parallel bonds (fix bond/breakable) and
# once with flat joints (fix bond/flatjoint); prints UCS, tensile strength and
# their ratio for each (bench/README.md, "Flat joint against parallel bond").
#
#   bench/flat_joint/strength_ratio.sh SPECIMEN_DIR OUT_DIR [key=value ...]
#
# SPECIMEN_DIR holds a calibrate job's specimen/ball.data and ball_info.txt
# (`orchestrate --stage calibrate` writes one under
# runs/<case>/calibrate/jobs/calibration/specimen). key=value pairs override
# the parameters below (bond_modulus, stiffness_ratio, bond_tensile,
# bond_cohesion, bond_friction, moment_factor, elements, joint_friction,
# unbonded_frac, bond_gap (interfaces out to this surface gap / min radius),
# fj_extra (more keywords for the flat joint, e.g. fj_extra="joint_friction 0.8"),
# bond_extra (more keywords for both models, e.g. bond_extra="unbonded_seed 7"),
# models="parallel flatjoint", tests="ucs brazilian scb" to add the
# semi-circular bend test of the toughness check (scb_r=... its carve radius,
# default the disc's; scb_angle=... turns the ball about the load axis before
# carving, deg: another half disc from the same packing), ...).
set -eu
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
spec="$(cd "$1" && pwd)"
out="$2"
shift 2
exe="${LIGGGHTS_MILL:-$root/build/bin/liggghts-mill}"
[ -x "$exe" ] || { echo "strength_ratio: $exe not found: run ./scripts/build.sh" >&2; exit 2; }
[ -f "$spec/ball.data" ] || { echo "strength_ratio: $spec/ball.data not found" >&2; exit 2; }

# The sandstone card and the reference calibration's bonds (bench/README.md).
E=18.69e9 nu=0.18 density=2580 restitution=0.5 friction=0.5
ucs_target=50e6 tensile_target=5e6
bond_modulus=9.9925879e10 stiffness_ratio=3.9440781 bond_tensile=24943466
bond_cohesion=49886932 bond_friction=30 moment_factor=0 radius_mult=1.0
bond_gap=0.15 max_bonds=16 rate=2 elements="1 3" joint_friction=-1 unbonded_frac=0
fj_extra="" bond_extra="" models="parallel flatjoint" tests="ucs brazilian"
ucs_r=0.0131578 disc_r=0.0209757 scb_angle=0
for kv in "$@"; do
  key=${kv%%=*}
  case "$key" in *[!a-zA-Z_]* | "") echo "strength_ratio: '$kv' is not key=value" >&2; exit 2 ;; esac
  eval "$key=\${kv#*=}"
done

mean_r=$(awk '{for (i = 1; i < NF; ++i) if ($i == "mean_radius") print $(i + 1)}' "$spec/ball_info.txt")
mkdir -p "$out"
out="$(cd "$out" && pwd)"

# The model's keywords (the decks' fix line is bond/${bond_style} with the
# model's own keywords in ${bond_model_keys}; docs/calibration.md, "The bond
# model").
model_keys() {  # model -> keywords
  if [ "$1" = flatjoint ]; then
    k="elements $elements"
    awk "BEGIN{exit !($joint_friction >= 0)}" && k="$k joint_friction $joint_friction"
    [ -n "$fj_extra" ] && k="$k $fj_extra"
  else
    k="moment_factor $moment_factor broken_contact no contact_moment no"
  fi
  [ -n "$bond_extra" ] && k="$k $bond_extra"
  echo "$k"
}

# test carve_r peak_strain cap model
run_test() {
  dir="$out/$4/$1"
  mkdir -p "$dir"
  deck=$1 pull=0
  [ "$1" = tension ] && deck=ucs pull=1  # the direct tension test: the UCS cylinder pulled
  cp "$root/liggghts_inputs/$deck.in.tmpl" "$dir/$1.in"
  peak=$3
  (cd "$dir" && "$exe" -in "$1.in" -log liggghts.log -screen none \
      -var pull "$pull" -var curve_file "$1_curve.txt" -var info_file "$1_info.txt" \
      -var specimen_file "$spec/ball.data" -var carve_r "$2" -var strain_rate "$rate" \
      -var max_strain "$(awk "BEGIN{print $5 * $peak}")" \
      -var sample_time "$(awk "BEGIN{print $peak / $rate / 300}")" \
      -var skin "$(awk "BEGIN{print 0.3 * $mean_r}")" \
      -var E "$E" -var nu "$nu" -var density "$density" -var restitution "$restitution" \
      -var friction "$friction" -var bond_modulus "$bond_modulus" \
      -var stiffness_ratio "$stiffness_ratio" -var bond_tensile "$bond_tensile" \
      -var bond_cohesion "$bond_cohesion" -var bond_friction "$bond_friction" \
      -var bond_style "$( [ "$4" = flatjoint ] && echo flatjoint || echo breakable )" \
      -var bond_model_keys "$(model_keys "$4")" -var radius_mult "$radius_mult" \
      -var bond_gap "$bond_gap" -var max_bonds "$max_bonds" -var unbonded_frac "$unbonded_frac" \
      -var deck_dir "$root/liggghts_inputs" \
      $( [ "$1" = scb ] && echo "-var carve_angle $scb_angle" )) ||
    { echo "strength_ratio: $4 $1 failed: see $dir/liggghts.log" >&2; exit 1; }
}

# Carve radii (element centres) of the reference calibration's cylinder and
# disc: diameter / 2 - mean element radius of its ucs_info.txt and
# brazilian_info.txt (override with ucs_r=... disc_r=... for another specimen).
for m in $models; do
  start=$(date +%s)
  case " $tests " in *" ucs "*)
    run_test ucs "$ucs_r" "$(awk "BEGIN{print $ucs_target / $E}")" "$m" 4.0 ;;
  esac
  case " $tests " in *" brazilian "*)
    run_test brazilian "$disc_r" "$(awk "BEGIN{print 4 * $tensile_target / $E}")" "$m" 5.0 ;;
  esac
  # The direct tension test (tests="... tension"): the UCS cylinder pulled apart by its end layers.
  case " $tests " in *" tension "*)
    run_test tension "$ucs_r" "$(awk "BEGIN{print $tensile_target / $E}")" "$m" 8.0 ;;
  esac
  # The toughness check's half disc (its radius: scb_r, default the disc's) (driver/stages/calibrate/lab_runs.cpp, LabBench::scb).
  case " $tests " in *" scb "*)
    run_test scb "${scb_r:-$disc_r}" "$(awk "BEGIN{print 4 * $tensile_target / $E}")" "$m" 10.0 ;;
  esac
  echo "$m: $(($(date +%s) - start)) s" > "$out/$m/seconds.txt"
done
/usr/bin/python3 "$here/strength_ratio.py" "$out" $models
