#!/bin/sh
# Real Slurm test: a one-node cluster on localhost runs the job-array
# scripts that `orchestrate hpc --stage breakage-report` writes for a
# three-impact breakage campaign, then the dependent merge job and the report
# job; checks every array task, the merge and the report job completed with
# exit 0 and the merged summary has one row per impact.
#
#   tests/hpc/test_slurm_array.sh ORCHESTRATE CASE_YAML WORKDIR
#
# Exit 77 (CTest: skipped) with the reason when the daemons cannot start here.
set -eu
orch=$1
case_file=$2
work=$3
here=$(cd "$(dirname "$0")" && pwd)
fail() { echo "FAIL: $*" >&2; exit 1; }

rm -rf "$work"
mkdir -p "$work"
work=$(cd "$work" && pwd)
cluster="$work/cluster"
run="$work/run"

"$here/slurm_cluster.sh" start "$cluster" >"$work/start.out" || exit $?
trap '"$here/slurm_cluster.sh" stop "$cluster"' EXIT INT TERM
export SLURM_CONF="$cluster/slurm.conf"
PATH="$PATH:/usr/sbin"

"$orch" --case "$case_file" --output "$run" --stage breakage-report --np 1 hpc --scheduler slurm --time 00:10:00
n=$("$orch" --case "$case_file" --output "$run" --stage breakage --list-tasks | wc -l)
[ "$n" -eq 3 ] || fail "expected 3 tasks from --list-tasks, got $n"

out=$(sh "$run/hpc/submit_breakage-report.sh")
echo "$out"
array=$(echo "$out" | sed -n 's/^breakage: array job \([0-9]*\) (3 tasks), merge job \([0-9]*\)$/\1/p')
merge=$(echo "$out" | sed -n 's/^breakage: array job \([0-9]*\) (3 tasks), merge job \([0-9]*\)$/\2/p')
report=$(echo "$out" | sed -n 's/^report: job \([0-9]*\)$/\1/p')
[ -n "$array" ] && [ -n "$merge" ] && [ -n "$report" ] || fail "could not read the job ids from: $out"

# Wait for the queue to drain (at most 10 min), printing it now and then.
t=0
while [ -n "$(squeue -h -o '%i' 2>/dev/null)" ]; do
  [ $t -ge 600 ] && { squeue; fail "jobs still queued after 600 s"; }
  [ $((t % 30)) -eq 0 ] && squeue -h -o '%i %j %T %M' | sed 's/^/  queue: /'
  sleep 2
  t=$((t + 2))
done

# Every array task and the merge job: COMPLETED, exit 0 (the controller keeps
# finished jobs for MinJobAge = 600 s, so scontrol still knows them).
state_of() { scontrol show job "$1" 2>/dev/null | tr ' ' '\n' | sed -n "s/^$2=//p" | head -n 1; }
for i in 0 1 2; do
  s=$(state_of "${array}_$i" JobState)
  e=$(state_of "${array}_$i" ExitCode)
  echo "array task $i: $s exit $e"
  [ "$s" = COMPLETED ] && [ "$e" = 0:0 ] || {
    cat "$run"/hpc/logs/*_"${array}_$i".out >&2 || true
    fail "array task $i ended $s with exit $e"
  }
done
s=$(state_of "$merge" JobState)
e=$(state_of "$merge" ExitCode)
echo "merge job: $s exit $e"
[ "$s" = COMPLETED ] && [ "$e" = 0:0 ] || { cat "$run"/hpc/logs/*merge*.out >&2 || true; fail "merge job ended $s with exit $e"; }

s=$(state_of "$report" JobState)
e=$(state_of "$report" ExitCode)
echo "report job: $s exit $e"
[ "$s" = COMPLETED ] && [ "$e" = 0:0 ] || { cat "$run"/hpc/logs/*report*.out >&2 || true; fail "report job ended $s with exit $e"; }

# The merge found every job done (it runs none itself: --merge-only).
grep -q "stage 'breakage': all 3 job(s) done; merged." "$run"/hpc/logs/*merge_"$merge".out ||
  fail "merge job did not find the three impacts done: $(cat "$run"/hpc/logs/*merge_"$merge".out)"

rows=$(($(wc -l <"$run/breakage/summary.csv") - 1))
[ "$rows" -eq 3 ] || fail "merged breakage/summary.csv has $rows rows, expected 3"
for v in 1 20 150; do
  grep -q "^$v,90,0," "$run/breakage/summary.csv" || fail "no row for $v m/s in the merged summary"
done
[ -s "$run/breakage/breakage.h5" ] || fail "no merged breakage.h5"
[ -s "$run/report/index.html" ] || fail "the report job wrote no report"
echo "PASS: 3 array tasks, the merge and the report job completed; summary.csv has 3 rows"
