#!/usr/bin/env bash
# Proves the single-node test cluster works end to end: start it, run a 4-task array job, check each
# task's output, stop it. Needs no accounting (sacct): the job's tasks are checked through
# `scontrol show job` and the files they wrote.
# Exit 0 on success, 1 on failure, 77 (skip) when slurm_cluster.sh cannot start a cluster here.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
readonly tasks=4
readonly job_timeout=60 # seconds for the whole array to leave the queue

now() { echo "${EPOCHREALTIME/,/.}"; }
elapsed() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.1f", b - a }'; }

work=$(mktemp -d "${TMPDIR:-/tmp}/deformkit-slurm-smoke.XXXXXX")
chmod 755 "$work" # munged wants every folder above its socket searchable by all users
cluster=$work/cluster
cleanup() {
    local stopped=0
    bash "$here/slurm_cluster.sh" stop "$cluster" || stopped=$?
    rm -rf "$work"
    if [ "$stopped" -ne 0 ]; then
        echo "slurm_smoke: FAIL: cluster daemons left running" >&2
        exit 1
    fi
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM
trap '' PIPE # a reader that went away must not skip the cleanup

fail() {
    echo "slurm_smoke: FAIL: $*" >&2
    if [ -n "${jobid:-}" ]; then
        echo "--- scontrol show job $jobid (one line per task)" >&2
        scontrol -o show job "$jobid" 2>&1 | awk '{ for (i = 1; i <= NF; i++)
            if ($i ~ /^(ArrayTaskId|JobState|Reason|ExitCode|StdOut)=/) printf "%s ", $i; print "" }' >&2 || true
    fi
    local f
    for f in "$work"/out/* "$cluster"/log/slurmctld.log "$cluster"/log/slurmd.log; do
        [ -s "$f" ] || continue
        echo "--- tail of ${f#"$work"/}" >&2
        tail -n 20 "$f" >&2
    done
    exit 1
}

t0=$(now)
rc=0
bash "$here/slurm_cluster.sh" start "$cluster" || rc=$?
if [ "$rc" -eq 77 ]; then exit 77; fi
[ "$rc" -eq 0 ] || fail "slurm_cluster.sh start exited $rc"
echo "slurm_smoke: start took $(elapsed "$t0") s"
# shellcheck source=/dev/null # written by slurm_cluster.sh start
source "$cluster/env.sh"

mkdir -p "$work/out" "$work/results"
t0=$(now)
# Each task writes a file named by its array index holding that index (expanded by the task's shell).
# shellcheck disable=SC2016
jobid=$(sbatch --parsable --array=1-$tasks --chdir="$work/results" -o "$work/out/%A_%a.out" \
    --wrap 'echo "$SLURM_ARRAY_TASK_ID" >"$SLURM_ARRAY_TASK_ID"') || fail "sbatch failed"
jobid=${jobid%%;*}
[[ $jobid =~ ^[0-9]+$ ]] || fail "sbatch --parsable printed '$jobid', expected a job id"

deadline=$((SECONDS + job_timeout))
while :; do
    if queued=$(squeue -h -j "$jobid" 2>&1); then
        [ -n "$queued" ] || break
    elif [[ $queued == *"Invalid job id"* ]]; then
        break # already purged from the controller: finished
    fi
    [ "$SECONDS" -lt "$deadline" ] || fail "job $jobid still queued after $job_timeout s: $queued"
    sleep 0.2
done
echo "slurm_smoke: array job $jobid ($tasks tasks) submitted and finished in $(elapsed "$t0") s"

# One line per array task; every one must have completed with exit code 0.
records=$(scontrol -o show job "$jobid") || fail "scontrol show job $jobid failed"
completed=$(grep -c 'JobState=COMPLETED .*ExitCode=0:0' <<<"$records" || true)
[ "$completed" -eq "$tasks" ] ||
    fail "$completed of $tasks tasks COMPLETED with exit 0:0 according to scontrol"

for i in $(seq 1 $tasks); do
    f=$work/results/$i
    [ -f "$f" ] || fail "task $i wrote no file $f"
    content=$(cat "$f")
    [ "$content" = "$i" ] || fail "task $i wrote '$content' into $f, expected '$i'"
done
n=$(find "$work/results" -type f | wc -l)
[ "$n" -eq "$tasks" ] || fail "$n files in results, expected $tasks"
echo "slurm_smoke: PASS ($tasks tasks, files and scontrol states checked)"
