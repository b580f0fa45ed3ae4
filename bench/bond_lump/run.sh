#!/bin/sh
# Benchmark of fix bond/breakable: bonded lump vs the same lump
# without bonds, one core each, one after the other.
# Usage: [VEL=150] [STEPS=60000] bench/bond_lump/run.sh [BUILD_DIR] [WORK_DIR]
#   BUILD_DIR defaults to ./build (needs bin/ or liggghts_styles/ liggghts-mill)
#   WORK_DIR  defaults to a fresh temporary directory
set -eu
here=$(cd "$(dirname "$0")" && pwd)
build=${1:-build}
exe=""
for c in "$build/bin/liggghts-mill" "$build/liggghts_styles/liggghts-mill"; do
  if [ -x "$c" ]; then exe=$(cd "$(dirname "$c")" && pwd)/liggghts-mill; break; fi
done
[ -n "$exe" ] || { echo "liggghts-mill not found under $build" >&2; exit 1; }
work=${2:-$(mktemp -d /tmp/bond_lump_XXXXXX)}
mkdir -p "$work"
cp "$here/lump_impact.in" "$work/"
cd "$work"
for b in 1 0; do
  /usr/bin/time -v "$exe" -in lump_impact.in -var bonds $b -var vel "${VEL:-150}" \
    -var steps "${STEPS:-60000}" -log log.bonds$b > out.bonds$b 2>&1
done
report() {
  f=out.bonds$1
  loop=$(sed -n 's/^Loop time of \([0-9.e+-]*\) on .* for \([0-9]*\) steps with \([0-9]*\) atoms.*/\1 \2/p' $f | tail -n 1)
  atoms0=$(awk '/^ *Step/{getline; print $2; exit}' $f)
  wall=$(sed -n 's/.*Elapsed (wall clock) time (h:mm:ss or m:ss): //p' $f)
  rss=$(sed -n 's/.*Maximum resident set size (kbytes): //p' $f)
  set -- $loop
  rate=$(awk -v t="$1" -v s="$2" -v n="$atoms0" 'BEGIN{printf "%.3g", n*s/t}')
  echo "bonds=$b loop_s=$1 steps=$2 atoms=$atoms0 element_steps_per_s=$rate wall=$wall peak_rss_kB=$rss"
}
b=1; r1=$(report 1); echo "$r1"
b=0; r0=$(report 0); echo "$r0"
t1=$(echo "$r1" | sed 's/.*loop_s=\([^ ]*\).*/\1/'); t0=$(echo "$r0" | sed 's/.*loop_s=\([^ ]*\).*/\1/')
awk -v a="$t1" -v b="$t0" 'BEGIN{printf "ratio bonded/plain (loop time) = %.3f\n", a/b}'
echo "load average after the runs: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "outputs in $work"
