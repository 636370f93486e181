#!/usr/bin/env bash
# Usage: farm_kill_test.sh DEFORMKIT SCRATCH_DIR
# A farm task killed with SIGKILL mid-way leaves only complete outputs, and running it again finishes
# with the bytes of an uninterrupted `deformkit eval`: `deformkit farm run` is idempotent and its writes
# are atomic. Exit 0 on success, 1 on failure.
set -u
dk=$1
work=$2
readonly frames=40
readonly side=245 # 245 x 245 = 60025 vertices: a few seconds for the task's 40 frames
rm -rf "$work" && mkdir -p "$work"
fail() {
    echo "farm_kill: FAIL: $*" >&2
    exit 1
}

# A grid in the XY plane, x in [-0.5, 0.5], y in [-1, 1], quads; OBJ indices from 1.
awk -v n="$side" 'BEGIN {
    for (j = 0; j < n; j++) for (i = 0; i < n; i++)
        printf "v %.6f %.6f 0\n", i / (n - 1) - 0.5, 2 * j / (n - 1) - 1
    for (j = 0; j + 1 < n; j++) for (i = 0; i + 1 < n; i++) {
        a = j * n + i + 1
        printf "f %d %d %d %d\n", a, a + 1, a + n + 1, a + n
    }
}' >"$work/grid.obj"
cat >"$work/shot.json" <<EOF
{"deformkit_scene": 1, "frames": [1, $frames], "objects": [
  {"name": "grid", "mesh": "grid.obj", "stack": [
    {"type": "twist", "params": {"handleY": [0, 1, 0],
      "endAngle": {"keys": [{"frame": 1, "value": 0}, {"frame": $frames, "value": 3}]}}}]}]}
EOF

"$dk" eval "$work/shot.json" --out "$work/eval" >"$work/eval.log" 2>&1 || fail "deformkit eval failed: $(tail -n 3 "$work/eval.log")"
"$dk" farm plan "$work/shot.json" --frames "1-$frames" --chunk "$frames" --out "$work/tasks" \
    --plan "$work/plan.json" >"$work/plan.log" 2>&1 || fail "farm plan failed: $(cat "$work/plan.log")"

# Run the one task in the background; kill it as soon as its first output appears.
"$dk" farm run "$work/plan.json" --task 0 >"$work/run1.log" 2>&1 &
pid=$!
deadline=$((SECONDS + 60))
until [ -e "$work/tasks/grid.0001.obj" ]; do
    kill -0 "$pid" 2>/dev/null || break
    [ "$SECONDS" -lt "$deadline" ] || { kill -KILL "$pid"; fail "no output after 60 s"; }
    sleep 0.01
done
sleep 0.3 # a few frames in, most likely in the middle of writing one
kill -KILL "$pid" 2>/dev/null
wait "$pid" 2>/dev/null
rc=$?
[ "$rc" -eq 137 ] || fail "the task exited $rc before it was killed (expected 137, killed mid-way): make it longer"

# Visible files are complete outputs only: each equals the uninterrupted run's file. Temporaries of the
# killed run, if any, are hidden (.grid.tmp-*).
done_before=0
for f in "$work"/tasks/*; do
    [ -e "$f" ] || continue
    name=${f##*/}
    [[ $name =~ ^grid\.[0-9]{4}\.obj$ ]] || fail "unexpected visible file $name after the kill"
    cmp -s "$f" "$work/eval/$name" || fail "$name after the kill differs from eval's (a partial file?)"
    done_before=$((done_before + 1))
done
hidden=$(find "$work/tasks" -name '.*' -type f | wc -l)
if [ "$done_before" -lt 1 ] || [ "$done_before" -ge "$frames" ]; then
    fail "$done_before of $frames outputs when killed (expected some, not all)"
fi

# Run it again to completion: the finished frames are skipped, the rest written.
"$dk" farm run "$work/plan.json" --task 0 >"$work/run2.log" 2>"$work/run2.err" || fail "rerun exited $?: $(cat "$work/run2.err")"
skipped=$(grep -c '"status":"skipped"' "$work/run2.log")
written=$(grep -c '"status":"written"' "$work/run2.log")
[ "$skipped" -eq "$done_before" ] || fail "rerun skipped $skipped frames, expected $done_before"
[ $((skipped + written)) -eq "$frames" ] || fail "rerun logged $((skipped + written)) frames, expected $frames"
for f in $(seq 1 "$frames"); do
    name=$(printf 'grid.%04d.obj' "$f")
    [ -f "$work/tasks/$name" ] || fail "$name missing after the rerun"
    cmp -s "$work/tasks/$name" "$work/eval/$name" || fail "$name differs from eval's"
done
n=$(find "$work/tasks" -maxdepth 1 -type f -name 'grid.*.obj' | wc -l)
[ "$n" -eq "$frames" ] || fail "$n outputs, expected $frames"
# Two runs of the same task at once (a scheduler's requeue while the first still runs): each frame is
# written whole by one of them or the other, never a mix, and both exit 0.
"$dk" farm plan "$work/shot.json" --frames "1-$frames" --chunk "$frames" --out "$work/twice" \
    --plan "$work/plan2.json" >"$work/plan2.log" 2>&1 || fail "farm plan failed: $(cat "$work/plan2.log")"
"$dk" farm run "$work/plan2.json" --task 0 >"$work/twice_a.log" 2>&1 &
pid_a=$!
"$dk" farm run "$work/plan2.json" --task 0 >"$work/twice_b.log" 2>&1 &
pid_b=$!
wait "$pid_a" || fail "the first of two concurrent runs exited $?: $(tail -n 3 "$work/twice_a.log")"
wait "$pid_b" || fail "the second of two concurrent runs exited $?: $(tail -n 3 "$work/twice_b.log")"
for f in $(seq 1 "$frames"); do
    name=$(printf 'grid.%04d.obj' "$f")
    cmp -s "$work/twice/$name" "$work/eval/$name" || fail "$name after two concurrent runs differs from eval's"
done
leftover=$(find "$work/twice" -name '.*' -type f | wc -l)
[ "$leftover" -eq 0 ] || fail "$leftover temporaries left by two runs that both finished"
echo "farm_kill: PASS (killed after $done_before of $frames frames, $hidden hidden temporaries left;" \
    "rerun skipped $skipped, wrote $written; all $frames outputs equal eval's; two concurrent runs of the task" \
    "wrote eval's bytes)"
rm -rf "$work"
