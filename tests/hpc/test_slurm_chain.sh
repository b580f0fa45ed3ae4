#!/bin/sh
# Real Slurm test: the whole campaign of a tiny case as one chain of
# dependent jobs on a one-node cluster (slurm_cluster.sh), from
# `orchestrate hpc --stage all`: flow (array, 2 MPI ranks), sample, transport
# (array), calibrate, a planning job that sizes the breakage array from the
# transport's impact conditions, breakage (array), report.
#
# First submission: one breakage impact run is made to fail (a stand-in
# liggghts-mill, through MILL_LIGGGHTS, fails the first impact deck once). The
# chain must stop there: that array task FAILED, the breakage merge FAILED and
# names the task's Slurm job and log, the report never ran.
# Second submission of the same script: every job COMPLETED, the report
# exists, and no breakage job that was done is run again.
#
#   tests/hpc/test_slurm_chain.sh ORCHESTRATE CASE_YAML WORKDIR
#
# Exit 77 (CTest: skipped) with the reason when the daemons cannot start here.
set -eu
orch=$1
case_file=$2
work=$3
here=$(cd "$(dirname "$0")" && pwd)
fail() { echo "FAIL: $*" >&2; exit 1; }
t_start=$(date +%s)

rm -rf "$work"
mkdir -p "$work"
work=$(cd "$work" && pwd)
cluster="$work/cluster"
run="$work/run"
logs="$run/hpc/logs"

"$here/slurm_cluster.sh" start "$cluster" >"$work/start.out" || exit $?
trap '"$here/slurm_cluster.sh" stop "$cluster"' EXIT INT TERM
export SLURM_CONF="$cluster/slurm.conf"
PATH="$PATH:/usr/sbin"

# Every job the controller knows (finished ones too, for MinJobAge = 600 s):
# "<id> <name> <state> <exit>", <id> = ARRAYJOB_TASK for array tasks.
job_table() {
  scontrol -o show job 2>/dev/null | awk '{
    delete f
    for (i = 1; i <= NF; i++) { k = $i; sub(/=.*/, "", k); v = $i; sub(/^[^=]*=/, "", v); if (!(k in f)) f[k] = v }
    id = ("ArrayTaskId" in f) ? f["ArrayJobId"] "_" f["ArrayTaskId"] : f["JobId"]
    print id, f["JobName"], f["JobState"], f["ExitCode"]
  }'
}
# The jobs of one submission: ids above the mark taken before it.
jobs_after() { job_table | awk -v m="$1" '{ split($1, p, "_"); if (p[1] + 0 > m) print }'; }
mark() { job_table | awk '{ split($1, p, "_"); if (p[1] + 0 > m) m = p[1] + 0 } END { print m + 0 }'; }
# Wait (at most $1 s) until nothing is queued or running.
drain() {
  t=0
  while [ -n "$(squeue -h -o '%i' 2>/dev/null)" ]; do
    [ "$t" -ge "$1" ] && { squeue -o '%i %j %T %r'; fail "jobs still queued after $1 s"; }
    [ $((t % 30)) -eq 0 ] && squeue -h -o '%i %j %T %M %r' | sed 's/^/  queue: /'
    sleep 2
    t=$((t + 2))
  done
}
show_logs() { for f in "$logs"/*; do echo "== $f"; tail -n 30 "$f"; done >&2; }

# --- the scripts, written before any stage ran ---
"$orch" --case "$case_file" --output "$run" hpc --scheduler slurm --stage all --np 2 | tee "$work/hpc.out"
for f in flow.array.sh flow.merge.sh sample.sh transport.array.sh transport.merge.sh calibrate.sh \
  breakage.plan.sh breakage.array.sh breakage.merge.sh report.sh submit_all.sh; do
  [ -f "$run/hpc/$f" ] || fail "orchestrate hpc --stage all did not write $f"
done
# The breakage array size is not in its script: the planning job finds it.
! grep -q '^#SBATCH --array' "$run/hpc/breakage.array.sh" || fail "breakage.array.sh has an --array written by hand"
grep -q '^#SBATCH --ntasks=2$' "$run/hpc/flow.array.sh" || fail "the flow tasks do not ask for --np 2 ranks"

# --- first submission: one breakage impact fails ---
real=$(dirname "$orch")/liggghts-mill
cat >"$work/liggghts-fails-once" <<EOF
#!/bin/sh
# Test stand-in for liggghts-mill: the first breakage impact run fails, once.
case "\$*" in
  *impact.in.tmpl*) if mkdir "$work/failed-once" 2>/dev/null; then echo "injected failure (test)" >&2; exit 1; fi ;;
esac
exec "$real" "\$@"
EOF
chmod +x "$work/liggghts-fails-once"
m0=$(mark)
MILL_LIGGGHTS="$work/liggghts-fails-once" sh "$run/hpc/submit_all.sh" | tee "$work/submit1.out"
grep -q '^breakage: planning job [0-9]' "$work/submit1.out" || fail "no planning job submitted for breakage"
drain 900
jobs_after "$m0" | sort -t_ -k1,1n -k2,2n >"$work/jobs1.txt"
echo "first submission:"
sed 's/^/  /' "$work/jobs1.txt"
[ -d "$work/failed-once" ] || { show_logs; fail "no breakage impact ran in the first submission"; }

state_of() { awk -v n="$2" '$2 == n { print $3 " " $4 }' "$1"; }
for name in flow flow-merge sample transport transport-merge calibrate breakage-plan; do
  s=$(state_of "$work/jobs1.txt" "mill-tiny_hpc-$name")
  [ -n "$s" ] || fail "first submission: no job $name"
  echo "$s" | grep -qv '^COMPLETED 0:0$' && { show_logs; fail "first submission: $name ended: $s"; }
done
failed=$(awk '$2 == "mill-tiny_hpc-breakage" && $3 == "FAILED" { print $1 }' "$work/jobs1.txt")
[ "$(echo "$failed" | grep -c .)" -eq 1 ] || { show_logs; fail "expected exactly one failed breakage task, got '$failed'"; }
n1=$(awk '$2 == "mill-tiny_hpc-breakage"' "$work/jobs1.txt" | grep -c .)
n_ok1=$(awk '$2 == "mill-tiny_hpc-breakage" && $3 == "COMPLETED" && $4 == "0:0"' "$work/jobs1.txt" | grep -c . || true)
[ "$n_ok1" -eq $((n1 - 1)) ] || fail "the other breakage tasks did not all complete"
s=$(state_of "$work/jobs1.txt" mill-tiny_hpc-breakage-merge)
[ "${s%% *}" = FAILED ] || fail "the breakage merge ended '$s', expected FAILED after a failed task"
s=$(state_of "$work/jobs1.txt" mill-tiny_hpc-report)
[ -n "$s" ] && [ "${s%% *}" != COMPLETED ] || fail "the report job ended '$s': the chain did not stop"
[ ! -e "$run/report/index.html" ] || fail "a report was written although a breakage task failed"
# The merge job's output names the failed task's Slurm job and its log.
merge_log=$(ls "$logs"/mill-tiny_hpc-breakage-merge_*.out)
failed_log="$logs/mill-tiny_hpc-breakage_$failed.out"
grep -q "scheduler job $failed, log $failed_log" "$merge_log" ||
  { cat "$merge_log" >&2; fail "the merge output does not name job $failed and its log $failed_log"; }
grep -rq "injected failure" "$run/breakage/jobs" || fail "the failed task's engine output is not in its job folder"
grep -q "the chain stops here" "$merge_log" || fail "the merge output does not say the chain stops"

# The array size came from the transport's impact conditions.
"$orch" --case "$case_file" --output "$run" --stage breakage --list-tasks >"$work/tasks.txt"
n_plan=$(grep -c '^[0-9]' "$work/tasks.txt")
[ "$n1" -eq "$n_plan" ] || fail "the breakage array had $n1 tasks, the plan after transport has $n_plan"
grep -q "stage breakage: $n_plan jobs, planned from the outputs of transport" "$logs"/mill-tiny_hpc-breakage-plan_*.out ||
  fail "the planning job did not report $n_plan jobs from the transport"
grep -q '^[0-9]*	rpm2000_b' "$work/tasks.txt" || fail "the breakage jobs are not the transport's binned conditions: $(cat "$work/tasks.txt")"

# --- second submission of the same script: resumes and finishes ---
done_before=$(for d in "$run"/breakage/jobs/*/; do
  [ "$(head -n 1 "$d/STATUS")" = done ] && echo "$d $(stat -c %Y "$d/STATUS")"
done || true)
m1=$(mark)
sh "$run/hpc/submit_all.sh" | tee "$work/submit2.out"
drain 900
jobs_after "$m1" | sort -t_ -k1,1n -k2,2n >"$work/jobs2.txt"
echo "second submission:"
sed 's/^/  /' "$work/jobs2.txt"
for name in flow flow-merge sample transport transport-merge calibrate breakage-plan breakage breakage-merge report; do
  grep -q " mill-tiny_hpc-$name " "$work/jobs2.txt" || fail "second submission: no job $name"
done
awk '$3 != "COMPLETED" || $4 != "0:0"' "$work/jobs2.txt" | grep -q . &&
  { show_logs; fail "second submission: not every job COMPLETED with exit 0"; }
n2=$(awk '$2 == "mill-tiny_hpc-breakage"' "$work/jobs2.txt" | grep -c .)
[ "$n2" -eq "$n_plan" ] || fail "second breakage array had $n2 tasks, expected $n_plan"
[ -s "$run/report/index.html" ] || fail "no report after the second submission"
[ -s "$run/breakage/product.csv" ] || fail "no breakage/product.csv"
rows=$(($(wc -l <"$run/breakage/summary.csv") - 1))
[ "$rows" -eq "$n_plan" ] || fail "merged breakage/summary.csv has $rows rows, expected $n_plan"
# Done jobs were skipped, not run again.
echo "$done_before" | while read -r d t; do
  [ -n "$d" ] || continue
  [ "$(stat -c %Y "$d/STATUS")" = "$t" ] || fail "breakage job $d was run again"
done
[ "$(echo "$done_before" | grep -c .)" -eq $((n_plan - 1)) ] || fail "expected $((n_plan - 1)) breakage jobs done before the resubmission"
grep -q '"np": 2' "$run/flow/rpm2000/flow_report.json" || fail "the flow did not run on 2 MPI ranks"
echo "PASS: whole chain on Slurm ($n_plan breakage tasks from the transport's conditions); a failed task stopped it," \
  "the resubmission finished it; $(($(date +%s) - t_start)) s"
