#!/usr/bin/env bash
# Starts and stops a throw-away single-node Slurm cluster on this machine, for tests of the render farm
# submission path. Every file of the cluster (munge key and socket, slurm.conf, state, spool, logs,
# pid files) lives under DIR, so two clusters never share anything but the ports 6817/6818.
#
#   slurm_cluster.sh start DIR   DIR must be empty or absent. Starts munged, slurmctld and slurmd, waits
#                                until the node is idle and writes DIR/env.sh (source it before sbatch).
#   slurm_cluster.sh stop DIR    Cancels leftover jobs, stops the daemons by their saved PIDs and waits
#                                until they are gone. A no-op when nothing runs.
#
# Exit 0 on success, 77 when the cluster cannot run here (Slurm or munge missing, not root, ports taken,
# cluster not up in time: ctest's "skipped"), 2 for a usage error, 1 when stop could not end a daemon.
# DEFORMKIT_SLURM_HOST overrides the node name (default: `hostname -s`, or localhost if that does not
# resolve).
set -euo pipefail

readonly ctld_port=6817
readonly slurmd_port=6818
readonly up_timeout=30   # seconds for munged, then for the node to turn idle
readonly stop_timeout=10 # seconds per daemon after SIGTERM before SIGKILL

skip() {
    echo "slurm_cluster: skipped: $*" >&2
    exit 77
}
usage() {
    echo "usage: slurm_cluster.sh start|stop DIR" >&2
    exit 2
}
now() { echo "${EPOCHREALTIME/,/.}"; }
elapsed() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.1f", b - a }'; }

# True while PID runs (a zombie counts as gone) and its command line names this cluster's DIR, so a
# recycled PID of some other process is never signalled.
ours() {
    local pid=$1 dir=$2 state
    [ -r "/proc/$pid/stat" ] || return 1
    state=$(awk '{ print $3 }' "/proc/$pid/stat" 2>/dev/null) || return 1
    [ "$state" != Z ] || return 1
    tr '\0' ' ' 2>/dev/null <"/proc/$pid/cmdline" | grep -qF -- "$dir/"
}

# LISTEN sockets on PORT in this network namespace, read from /proc so no extra tool is needed.
portTaken() {
    local hex
    hex=$(printf '%04X' "$1")
    awk -v p=":$hex" 'FNR > 1 && substr($2, length($2) - 4) == p && $4 == "0A" { found = 1 }
        END { exit !found }' /proc/net/tcp /proc/net/tcp6 2>/dev/null
}

logTail() { # logTail DIR DAEMON...: last lines of each daemon's log (its stderr if the log is empty)
    local dir=$1 name f
    shift
    for name in "$@"; do
        f=$dir/log/$name.log
        [ -s "$f" ] || f=$dir/log/$name.out
        [ -s "$f" ] || continue
        echo "--- tail of $f" >&2 || true
        tail -n 15 "$f" >&2 || true
    done
}

stopCluster() {
    local dir=$1 name pid t0 deadline left=()
    [ -d "$dir/pids" ] || return 0
    t0=$(now)
    # Jobs still running would keep their slurmstepd and task processes after slurmd exits.
    pid=$(cat "$dir/pids/slurmctld.pid" 2>/dev/null || true)
    if [ -n "$pid" ] && ours "$pid" "$dir"; then
        local jobs
        jobs=$(SLURM_CONF="$dir/slurm.conf" timeout 5 squeue -h -o %A 2>/dev/null || true)
        if [ -n "$jobs" ]; then
            # shellcheck disable=SC2086 # one job id per word
            SLURM_CONF="$dir/slurm.conf" timeout 5 scancel $jobs 2>/dev/null || true
            deadline=$((SECONDS + 5))
            while [ -n "$(SLURM_CONF="$dir/slurm.conf" timeout 5 squeue -h -o %A 2>/dev/null)" ] &&
                [ "$SECONDS" -lt "$deadline" ]; do
                sleep 0.2
            done
        fi
    fi
    # slurmd and slurmctld first: they still talk to munged while shutting down.
    for name in slurmd slurmctld munged; do
        [ -f "$dir/pids/$name.pid" ] || continue
        pid=$(cat "$dir/pids/$name.pid")
        if ours "$pid" "$dir"; then
            kill -TERM "$pid" 2>/dev/null || true
            deadline=$((SECONDS + stop_timeout))
            while ours "$pid" "$dir" && [ "$SECONDS" -lt "$deadline" ]; do sleep 0.05; done
            if ours "$pid" "$dir"; then
                kill -KILL "$pid" 2>/dev/null || true
                deadline=$((SECONDS + 2))
                while ours "$pid" "$dir" && [ "$SECONDS" -lt "$deadline" ]; do sleep 0.05; done
            fi
        fi
        if ours "$pid" "$dir"; then
            left+=("$name ($pid)")
        else
            rm -f "$dir/pids/$name.pid"
        fi
    done
    if ((${#left[@]})); then
        echo "slurm_cluster: could not stop ${left[*]}" >&2
        return 1
    fi
    echo "slurm_cluster: stopped in $(elapsed "$t0") s" >&2
}

abortStart() {
    if [ "$1" -ne 0 ]; then stopCluster "$starting" >/dev/null 2>&1 || true; fi
}

startCluster() {
    local dir=$1 host t0 missing=() b
    for b in munged munge unmunge slurmctld slurmd sbatch squeue sinfo scontrol scancel; do
        command -v "$b" >/dev/null 2>&1 || missing+=("$b")
    done
    ((${#missing[@]} == 0)) || skip "not found on PATH: ${missing[*]} (apt-get install slurm-wlm munge)"
    [ "$(id -u)" -eq 0 ] || skip "the test cluster runs its daemons as root; running as uid $(id -u)"
    portTaken "$ctld_port" && skip "port $ctld_port is taken (another slurmctld running?)"
    portTaken "$slurmd_port" && skip "port $slurmd_port is taken (another slurmd running?)"

    mkdir -p "$dir"
    dir=$(cd "$dir" && pwd)
    if [ -n "$(ls -A "$dir")" ]; then
        echo "slurm_cluster: $dir is not empty; start needs a fresh folder" >&2
        exit 2
    fi
    # munged also demands that every folder above its socket be searchable by all users.
    local p=$dir
    while [ "$p" != / ]; do
        p=$(dirname "$p")
        case $(stat -c %A "$p") in
        *x | *t) ;;
        *)
            echo "slurm_cluster: $p is not searchable by all users (chmod o+x), which munged requires" >&2
            exit 2
            ;;
        esac
    done
    host=${DEFORMKIT_SLURM_HOST:-$(hostname -s 2>/dev/null || uname -n)}
    host=${host%%.*}
    if [ -z "${DEFORMKIT_SLURM_HOST:-}" ] && ! getent hosts "$host" >/dev/null 2>&1; then
        host=localhost
    fi
    t0=$(now)

    # From here on a failed start stops whatever it started; the logs stay in DIR for the caller.
    starting=$dir
    trap 'abortStart $?' EXIT
    # Signals end the script through exit so the EXIT trap runs; a closed stderr (a reader that went
    # away) must not kill it before that either.
    trap 'exit 130' INT
    trap 'exit 143' TERM
    trap 'exit 129' HUP
    trap '' PIPE

    mkdir -p "$dir"/{munge,pids,run,log,state,spool}
    # munged refuses a socket folder that is not executable by everyone.
    chmod 755 "$dir" "$dir/munge"
    if command -v mungekey >/dev/null 2>&1; then
        mungekey --create --keyfile="$dir/munge/munge.key"
    else
        dd if=/dev/urandom of="$dir/munge/munge.key" bs=1024 count=1 status=none
    fi
    chmod 400 "$dir/munge/munge.key"
    local socket=$dir/munge/munge.socket
    munged -F --key-file="$dir/munge/munge.key" --socket="$socket" --pid-file="$dir/run/munged.pid" \
        --log-file="$dir/log/munged.log" --seed-file="$dir/munge/munge.seed" \
        </dev/null >>"$dir/log/munged.out" 2>&1 &
    echo $! >"$dir/pids/munged.pid"
    local deadline=$((SECONDS + up_timeout))
    until munge -S "$socket" -n 2>/dev/null | unmunge -S "$socket" >/dev/null 2>&1; do
        if ! ours "$(cat "$dir/pids/munged.pid")" "$dir" || [ "$SECONDS" -ge "$deadline" ]; then
            echo "slurm_cluster: skipped: munged did not come up (log: $dir/log/munged.log)" >&2
            logTail "$dir" munged
            exit 77
        fi
        sleep 0.05
    done

    cat >"$dir/slurm.conf" <<EOF
# Single-node test cluster; every path is under this folder.
ClusterName=deformkit-test
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$socket
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/run/slurmctld.pid
SlurmdPidFile=$dir/run/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
MailProg=/bin/true
SchedulerType=sched/backfill
SchedulerParameters=batch_sched_delay=0
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
# Trust the CPU count below even where slurmd detects a different layout (containers, VMs).
SlurmdParameters=config_overrides
NodeName=$host CPUs=$(nproc) State=UNKNOWN
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF

    export SLURM_CONF=$dir/slurm.conf
    launch() { # launch DAEMON: starts slurmctld or slurmd in the foreground of a background job
        case $1 in
        slurmctld) slurmctld -D -i -f "$SLURM_CONF" </dev/null >>"$dir/log/slurmctld.out" 2>&1 & ;;
        slurmd) slurmd -D -N "$host" -f "$SLURM_CONF" </dev/null >>"$dir/log/slurmd.out" 2>&1 & ;;
        esac
        echo $! >"$dir/pids/$1.pid"
    }
    launch slurmctld
    launch slurmd

    local state="" resumed=0 relaunched=""
    deadline=$((SECONDS + up_timeout))
    while :; do
        for b in slurmctld slurmd; do
            if ! ours "$(cat "$dir/pids/$b.pid")" "$dir"; then
                # Seen on this kind of machine: slurmctld now and then exits during its first second
                # without a log line, and a second start works. Relaunch each daemon once, showing what
                # it printed, before giving up.
                if [[ " $relaunched " != *" $b "* ]]; then
                    relaunched+=" $b"
                    echo "slurm_cluster: $b exited during start-up; starting it once more" >&2
                    logTail "$dir" "$b"
                    sleep 1
                    launch "$b"
                    continue
                fi
                echo "slurm_cluster: skipped: $b exited during start-up (logs: $dir/log)" >&2
                logTail "$dir" slurmctld slurmd
                exit 77
            fi
        done
        state=$(sinfo -h -n "$host" -o %t 2>/dev/null || true)
        case $state in
        idle) break ;;
        down | drain | drng | inval)
            # ReturnToService=2 normally does this; ask at most once a second.
            if [ "$SECONDS" -gt "$resumed" ]; then
                resumed=$SECONDS
                scontrol update nodename="$host" state=resume >/dev/null 2>&1 || true
            fi
            ;;
        esac
        if [ "$SECONDS" -ge "$deadline" ]; then
            echo "slurm_cluster: skipped: node $host not idle after ${up_timeout} s" \
                "(state '${state:-no answer}', logs: $dir/log)" >&2
            logTail "$dir" slurmctld slurmd
            exit 77
        fi
        sleep 0.1
    done

    cat >"$dir/env.sh" <<EOF
# Source this to talk to the test cluster in $dir.
# Variables inherited from an enclosing Slurm job would redirect or reshape submissions: drop them.
for v in \$(compgen -e | grep -E '^(SLURM|SBATCH|SALLOC|SRUN|SQUEUE|SINFO|SCONTROL|SCANCEL)_' || true); do
    unset "\$v"
done
unset v
export SLURM_CONF='$dir/slurm.conf'
export DEFORMKIT_SLURM_DIR='$dir'
export DEFORMKIT_SLURM_NODE='$host'
export DEFORMKIT_SLURM_PARTITION=debug
EOF
    echo "slurm_cluster: node $host idle in $(elapsed "$t0") s; source $dir/env.sh" >&2
    trap - EXIT INT TERM HUP PIPE
}

[ $# -eq 2 ] || usage
case $1 in
start) startCluster "$2" ;;
stop)
    [ -d "$2" ] || exit 0
    stopCluster "$(cd "$2" && pwd)"
    ;;
*) usage ;;
esac
