#!/usr/bin/env bash
# A single-node SLURM cluster on this machine, for tests/test_cluster.py and for trying the SLURM
# profile (workflow/profiles/slurm) without a real cluster.
#
#   tests/cluster/local_slurm.sh install   # once, as root: apt-get install slurm-wlm munge (Debian 12: SLURM 22.05)
#   tests/cluster/local_slurm.sh start     # munged, slurmctld, slurmd; returns once the node is idle with all its CPUs (<= 60 s)
#   eval "$(tests/cluster/local_slurm.sh env)"   # SLURM_CONF for sbatch, squeue, scontrol, snakemake
#   tests/cluster/local_slurm.sh status    # daemons, node and queue; exit 0 only if the cluster is up
#   tests/cluster/local_slurm.sh stop      # cancel jobs, stop the daemons, remove the state directory
#
# Everything lives under one state directory ($GEARDYN_SLURM_DIR, default /tmp/geardyn-slurm):
# slurm.conf, its own munge key and socket, spool and state directories, logs, pid files. The one
# thing outside it is the symlink /etc/slurm/slurm.conf -> $STATE/slurm.conf, made by `start` and
# removed by `stop`: the executor plugin's job step (snakemake-executor-plugin-slurm-jobstep) drops
# every SLURM_* variable, SLURM_CONF too, before it calls `srun` inside the job, so srun only finds
# the cluster at the default path, as on a real cluster. `start` refuses to replace an
# /etc/slurm/slurm.conf that is not its own symlink (a real installation). All daemons listen
# on localhost only (ports $GEARDYN_SLURM_PORT and +1, default 6817/6818). One node "localhost" with
# $GEARDYN_SLURM_CPUS CPUs (default: all of this machine's) in one partition "debug" (the default).
# No accounting database: job status comes from squeue (slurmctld keeps finished jobs for MinJobAge =
# 1800 s), see docs/operations.md. Must run as root (daemons run as root: SlurmUser = SlurmdUser = root).
# No cgroups (they are not available in every container): proctrack/linuxproc, task/none; memory
# requests are scheduled (CR_Core_Memory) but not enforced.
set -euo pipefail

STATE=${GEARDYN_SLURM_DIR:-/tmp/geardyn-slurm}
PORT=${GEARDYN_SLURM_PORT:-6817}
CPUS=${GEARDYN_SLURM_CPUS:-$(nproc)}
NODE=localhost
CONF=$STATE/slurm.conf
ETC_CONF=/etc/slurm/slurm.conf
SOCKET=$STATE/munge/munge.socket

die() { echo "local_slurm: $*" >&2; exit 1; }

pid_alive() {  # pid file -> 0 if the process in it runs
    [[ -s $1 ]] && kill -0 "$(cat "$1")" 2>/dev/null
}

need_binaries() {
    local missing=()
    for b in munged slurmctld slurmd sbatch squeue scontrol sinfo scancel; do
        command -v "$b" >/dev/null || missing+=("$b")
    done
    ((${#missing[@]} == 0)) || die "missing ${missing[*]}: run '$0 install' (apt-get install slurm-wlm munge)"
}

write_conf() {
    # RealMemory: what the machine has, less 1 GiB for the OS (slurmd drains a node that has less
    # memory than configured).
    local mem_mb
    mem_mb=$(awk '/^MemTotal:/ {printf "%d", $2 / 1024 - 1024}' /proc/meminfo)
    cat >"$CONF" <<EOF
# Written by tests/cluster/local_slurm.sh: a single-node cluster on localhost.
ClusterName=geardyn-local
SlurmctldHost=localhost(127.0.0.1)
SlurmctldPort=$PORT
SlurmdPort=$((PORT + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$SOCKET
StateSaveLocation=$STATE/ctld
SlurmdSpoolDir=$STATE/spool
SlurmctldPidFile=$STATE/slurmctld.pid
SlurmdPidFile=$STATE/slurmd.pid
SlurmctldLogFile=$STATE/log/slurmctld.log
SlurmdLogFile=$STATE/log/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
# no cgroups inside a container
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
SwitchType=switch/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
ReturnToService=2
# finished jobs stay visible to squeue/scontrol for 30 min: the executor plugin polls squeue (it needs
# at least 120 s), and tests/test_cluster.py reads each job's limits back with scontrol after a run
MinJobAge=1800
# a cancelled job's processes get SIGKILL 5 s after SIGTERM (default 30 s)
KillWait=5
# requeue nothing by itself: Snakemake's retries decide
JobRequeue=0
# a job that asks for more than the partition allows is refused at sbatch, not left pending
EnforcePartLimits=ALL
SchedulerParameters=sched_interval=1
NodeName=$NODE NodeAddr=127.0.0.1 NodeHostname=$NODE CPUs=$CPUS RealMemory=$mem_mb State=UNKNOWN
PartitionName=debug Nodes=$NODE Default=YES MaxTime=24:00:00 DefaultTime=00:10:00 State=UP
EOF
}

link_conf() {  # /etc/slurm/slurm.conf -> $CONF, unless a real configuration is there
    if [[ -L $ETC_CONF && $(readlink "$ETC_CONF") == "$CONF" ]]; then
        return
    fi
    if [[ -e $ETC_CONF || -L $ETC_CONF ]]; then
        die "$ETC_CONF exists and is not this script's link to $CONF: not replacing it"
    fi
    mkdir -p "$(dirname "$ETC_CONF")"
    ln -s "$CONF" "$ETC_CONF"
}

start_munge() {
    pid_alive "$STATE/munge/munged.pid" && return
    if [[ ! -s $STATE/munge/munge.key ]]; then
        dd if=/dev/urandom of="$STATE/munge/munge.key" bs=1024 count=1 status=none
        chmod 600 "$STATE/munge/munge.key"
    fi
    munged --force --key-file="$STATE/munge/munge.key" --socket="$SOCKET" \
        --pid-file="$STATE/munge/munged.pid" --log-file="$STATE/log/munged.log" \
        --seed-file="$STATE/munge/munged.seed"
}

wait_for() {  # seconds, description, command...
    local secs=$1 what=$2
    shift 2
    local i
    for ((i = 0; i < secs * 10; i++)); do
        "$@" >/dev/null 2>&1 && return 0
        sleep 0.1
    done
    die "$what did not happen within ${secs}s (logs: $STATE/log/)"
}

node_ready() {  # the node is idle and has registered all $CPUS CPUs (sinfo and scontrol agree)
    local state cpus
    read -r state cpus < <(sinfo -N -h -n "$NODE" -o "%T %c" 2>/dev/null) || return 1
    [[ $state == idle && $cpus == "$CPUS" ]] || return 1
    scontrol show node "$NODE" 2>/dev/null | grep -Eq "(^|[[:space:]])CPUTot=$CPUS([[:space:]]|$)"
}

wait_node_ready() {  # seconds: poll node_ready; on timeout one line with what sinfo shows
    local secs=$1 i
    for ((i = 0; i < secs * 10; i++)); do
        node_ready && return 0
        sleep 0.1
    done
    die "node $NODE not idle with $CPUS CPUs within ${secs}s (sinfo: '$(sinfo -N -h -n "$NODE" \
        -o "%T %c" 2>/dev/null || echo unreachable)'; logs: $STATE/log/)"
}

cmd_start() {
    [[ $(id -u) == 0 ]] || die "must run as root (SlurmUser=root)"
    need_binaries
    export SLURM_CONF=$CONF
    mkdir -p "$STATE"/{munge,ctld,spool,log}
    chmod 755 "$STATE" "$STATE/munge"  # the socket must be reachable; the key itself is 0600
    [[ -f $CONF ]] || write_conf
    link_conf
    start_munge
    wait_for 10 "munged start" test -S "$SOCKET"
    if ! pid_alive "$STATE/slurmctld.pid"; then
        slurmctld -f "$CONF"
    fi
    wait_for 20 "slurmctld start" scontrol ping
    if ! pid_alive "$STATE/slurmd.pid"; then
        slurmd -f "$CONF" -N "$NODE"
    fi
    wait_node_ready 60
    echo "local_slurm: up ($STATE; export SLURM_CONF=$CONF)"
}

kill_pidfile() {  # pid file, name: TERM, then KILL after 10 s
    local file=$1 name=$2 pid i
    [[ -s $file ]] || return 0
    pid=$(cat "$file")
    kill -0 "$pid" 2>/dev/null || return 0
    kill "$pid" 2>/dev/null || true
    for ((i = 0; i < 100; i++)); do
        kill -0 "$pid" 2>/dev/null || return 0
        sleep 0.1
    done
    echo "local_slurm: $name ($pid) did not stop on SIGTERM, killing" >&2
    kill -9 "$pid" 2>/dev/null || true
}

our_stepds() {  # slurmstepd processes of this cluster (they hold files under $STATE open)
    local proc comm
    for proc in /proc/[0-9]*; do
        read -r comm <"$proc/comm" 2>/dev/null || continue
        [[ $comm == slurmstepd* ]] || continue  # slurmstepd-wlm on Debian
        if ls -l "$proc/fd" 2>/dev/null | grep -q -- "$STATE/"; then
            echo "${proc#/proc/}"
        fi
    done
}

descendants() {  # pids... -> those pids and all their descendants
    ps -eo pid=,ppid= | awk -v roots="$*" '
        { parent[$1] = $2 }
        END {
            n = split(roots, r, " "); for (i = 1; i <= n; i++) keep[r[i]] = 1
            do { grew = 0; for (p in parent) if (!(p in keep) && (parent[p] in keep)) { keep[p] = 1; grew = 1 } } while (grew)
            for (p in keep) print p
        }'
}

cmd_stop() {
    export SLURM_CONF=$CONF
    if [[ -f $CONF ]] && pid_alive "$STATE/slurmctld.pid"; then
        scancel --full --quiet --user="$(id -un)" 2>/dev/null || true
        local i
        for ((i = 0; i < 150; i++)); do  # up to 15 s for running jobs to end
            [[ -z $(squeue -h -t running,completing -o %i 2>/dev/null) ]] && break
            sleep 0.1
        done
    fi
    kill_pidfile "$STATE/slurmd.pid" slurmd
    kill_pidfile "$STATE/slurmctld.pid" slurmctld
    kill_pidfile "$STATE/munge/munged.pid" munged
    # job steps that outlived the cancel (e.g. slurmctld was gone), with the job's processes:
    # slurmstepd is reparented to init, not a child of slurmd
    local stepds leftover
    mapfile -t stepds < <(our_stepds)
    if ((${#stepds[@]})); then
        mapfile -t leftover < <(descendants "${stepds[@]}")
        echo "local_slurm: killing leftover job steps ${stepds[*]} and their processes" >&2
        kill -9 "${leftover[@]}" 2>/dev/null || true
    fi
    if [[ -L $ETC_CONF && $(readlink "$ETC_CONF") == "$CONF" ]]; then
        rm -f "$ETC_CONF"
    fi
    rm -rf "$STATE"
    echo "local_slurm: stopped, $STATE removed"
}

cmd_status() {
    export SLURM_CONF=$CONF
    local ok=0 name file
    for name in munged slurmctld slurmd; do
        file=$STATE/$name.pid
        [[ $name == munged ]] && file=$STATE/munge/munged.pid
        if pid_alive "$file"; then
            echo "$name: running (pid $(cat "$file"))"
        else
            echo "$name: not running"
            ok=1
        fi
    done
    if ((ok == 0)); then
        sinfo -N -o "%N %P %T %c %m" || ok=1
        squeue -o "%i %j %T %M %l %m" || ok=1
    fi
    return $ok
}

cmd_install() {
    [[ $(id -u) == 0 ]] || die "must run as root"
    apt-get update
    DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends slurm-wlm munge
}

case ${1:-} in
start) cmd_start ;;
stop) cmd_stop ;;
status) cmd_status ;;
env) echo "export SLURM_CONF=$CONF" ;;
install) cmd_install ;;
*) die "usage: $0 {install|start|stop|status|env}" ;;
esac
