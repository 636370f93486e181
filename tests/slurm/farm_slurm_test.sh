#!/usr/bin/env bash
# Usage: farm_slurm_test.sh DEFORMKIT
# `deformkit farm submit --slurm` end to end on the single-node test cluster: plan a 6-frame twist of a
# grid followed by the UV warp, in chunks of 2 (3 mesh tasks and 3 UV-warp tasks of tile 1001), submit the
# job array, wait for it, and check every output against a local `deformkit eval` of the same scene over
# the task's frames byte for byte, and every array task's state in scontrol.
# Exit 0 on success, 1 on failure, 77 (skip) when slurm_cluster.sh cannot start a cluster here.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
dk=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
readonly frames=6 chunk=2 tasks=6
readonly job_timeout=120 # seconds for the whole array to leave the queue

work=$(mktemp -d "${TMPDIR:-/tmp}/deformkit-farm-slurm.XXXXXX")
chmod 755 "$work" # munged wants every folder above its socket searchable by all users
cluster=$work/cluster
cleanup() {
    local stopped=0
    bash "$here/slurm_cluster.sh" stop "$cluster" || stopped=$?
    rm -rf "$work"
    if [ "$stopped" -ne 0 ]; then
        echo "farm_slurm: FAIL: cluster daemons left running" >&2
        exit 1
    fi
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM
trap '' PIPE

fail() {
    echo "farm_slurm: FAIL: $*" >&2
    if [ -n "${jobid:-}" ]; then
        echo "--- scontrol show job $jobid (one line per task)" >&2
        scontrol -o show job "$jobid" 2>&1 | awk '{ for (i = 1; i <= NF; i++)
            if ($i ~ /^(ArrayTaskId|JobState|Reason|ExitCode)=/) printf "%s ", $i; print "" }' >&2 || true
    fi
    local f
    for f in "$work"/plan.*.log "$cluster"/log/slurmctld.log "$cluster"/log/slurmd.log; do
        [ -s "$f" ] || continue
        echo "--- tail of ${f#"$work"/}" >&2
        tail -n 20 "$f" >&2
    done
    exit 1
}

rc=0
bash "$here/slurm_cluster.sh" start "$cluster" || rc=$?
if [ "$rc" -eq 77 ]; then exit 77; fi
[ "$rc" -eq 0 ] || fail "slurm_cluster.sh start exited $rc"
# shellcheck source=/dev/null # written by slurm_cluster.sh start
source "$cluster/env.sh"

# The scene: a 21 x 41 grid in the XY plane with UVs in tile 1001, twisted about Y by an angle keyed over
# the 6 frames, then the UV warp with a 32 x 32 rigidity map (a rigid disk, as an 8-bit PGM).
awk -v nx=21 -v ny=41 'BEGIN {
    for (j = 0; j < ny; j++) for (i = 0; i < nx; i++)
        printf "v %.6f %.6f 0\n", i / (nx - 1) - 0.5, 2 * j / (ny - 1) - 1
    for (j = 0; j < ny; j++) for (i = 0; i < nx; i++)
        printf "vt %.6f %.6f\n", 0.05 + 0.9 * i / (nx - 1), 0.05 + 0.9 * j / (ny - 1)
    for (j = 0; j + 1 < ny; j++) for (i = 0; i + 1 < nx; i++) {
        a = j * nx + i + 1
        printf "f %d/%d %d/%d %d/%d %d/%d\n", a, a, a + 1, a + 1, a + nx + 1, a + nx + 1, a + nx, a + nx
    }
}' >"$work/grid.obj"
awk 'BEGIN { print "P2"; print "32 32"; print "255"
    for (y = 0; y < 32; y++) {
        for (x = 0; x < 32; x++) {
            dx = (x + 0.5) / 32 - 0.5; dy = (y + 0.5) / 32 - 0.5
            printf "%d ", (dx * dx + dy * dy < 0.04) ? 255 : 0
        }
        print ""
    } }' >"$work/rig.1001.pgm"
cat >"$work/shot.json" <<EOF
{"deformkit_scene": 1, "frames": [1, $frames], "objects": [
  {"name": "grid", "mesh": "grid.obj", "stack": [
    {"type": "twist", "params": {"handleY": [0, 1, 0],
      "endAngle": {"keys": [{"frame": 1, "value": 0}, {"frame": $frames, "value": 2}]}}},
    {"type": "uvwarp", "rigidity": "rig.<UDIM>.pgm", "params": {"iterations": 4}}]}]}
EOF

# The reference: eval over each task's frame range (with --warm-up 0 a UV-warp task starts cold at its
# first frame, as eval over the range does).
for first in $(seq 1 $chunk $frames); do
    "$dk" eval "$work/shot.json" --frames "$first-$((first + chunk - 1))" --out "$work/eval" --no-previews \
        >/dev/null || fail "deformkit eval --frames $first-$((first + chunk - 1)) failed"
done

"$dk" farm plan "$work/shot.json" --frames "1-$frames" --chunk $chunk --warm-up 0 --out "$work/tasks" \
    --plan "$work/plan.json" >/dev/null || fail "deformkit farm plan failed"
jobid=$("$dk" farm submit --slurm "$work/plan.json") || fail "deformkit farm submit failed"
[[ $jobid =~ ^[0-9]+$ ]] || fail "farm submit printed '$jobid', expected a job id"

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

records=$(scontrol -o show job "$jobid") || fail "scontrol show job $jobid failed"
completed=$(grep -c 'JobState=COMPLETED .*ExitCode=0:0' <<<"$records" || true)
[ "$completed" -eq "$tasks" ] || fail "$completed of $tasks tasks COMPLETED with exit 0:0 according to scontrol"

for f in $(seq 1 $frames); do
    for name in $(printf 'grid.%04d.obj grid.redirect.1001.%04d.exr' "$f" "$f"); do
        [ -f "$work/tasks/$name" ] || fail "$name was not written by the job"
        cmp -s "$work/tasks/$name" "$work/eval/$name" || fail "$name differs from deformkit eval's"
    done
done
n=$(find "$work/tasks" -type f | wc -l)
[ "$n" -eq $((2 * frames)) ] || fail "$n files in the output folder, expected $((2 * frames))"
# Each task logged one JSON line per frame of its chunk (a UV-warp task: per tile and frame, one tile here).
for k in $(seq 0 $((tasks - 1))); do
    log=$work/plan.${jobid}_$k.log
    lines=$(grep -E "\"task\":$k[,}]" "$log" | grep -c '"status":"written"' || true)
    [ "$lines" -eq $chunk ] || fail "task $k logged $lines written frames in $log, expected $chunk"
done
echo "farm_slurm: PASS (job $jobid: $tasks tasks COMPLETED, $((2 * frames)) outputs equal deformkit eval's)"
