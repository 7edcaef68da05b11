#!/usr/bin/env bash
# A one-node Slurm cluster on this machine, for tests and trials: munged,
# slurmctld and slurmd with their configuration, keys, spool, logs and PID
# files under DIR (munged's socket in a /tmp/campanile-munge.* directory,
# removed by stop), on ports of our own (nothing under /etc is touched).
#
#   deploy/slurm/one-node.sh start DIR [CTLD_PORT SLURMD_PORT]   # prints: export SLURM_CONF=DIR/slurm.conf
#   deploy/slurm/one-node.sh stop DIR                             # kills the three daemons by their PID files
#
# Needs Debian's slurm-wlm and munge (`apt install slurm-wlm munge`; .ci/run
# installs them). The daemons run as the calling user (root or not): jobs
# run as that user. `start` waits until the node is idle (30 s at most) and
# exits 1 with the daemons' logs when it is not.
set -euo pipefail
cmd="${1:-}"
dir="${2:-}"
[ -n "$cmd" ] && [ -n "$dir" ] || { echo "usage: one-node.sh start|stop DIR [CTLD_PORT SLURMD_PORT]" >&2; exit 2; }
stop() {
    for f in "$dir/slurmd.pid" "$dir/slurmctld.pid" "$dir/munge/munged.pid"; do
        if [ -f "$f" ]; then
            pid="$(cat "$f")"
            kill "$pid" 2>/dev/null || true
            for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
            kill -9 "$pid" 2>/dev/null || true
            rm -f "$f"
        fi
    done
    if [ -f "$dir/munge/socket-dir" ]; then
        rm -rf "$(cat "$dir/munge/socket-dir")"
        rm -f "$dir/munge/socket-dir"
    fi
}
case "$cmd" in
    stop) stop; exit 0 ;;
    start) ;;
    *) echo "one-node.sh: unknown command $cmd (start or stop)" >&2; exit 2 ;;
esac
for b in munged slurmctld slurmd sbatch sinfo; do
    command -v "$b" >/dev/null 2>&1 || [ -x "/usr/sbin/$b" ] || {
        echo "one-node.sh: $b not found: install Debian's slurm-wlm and munge (apt install slurm-wlm munge)" >&2
        exit 2
    }
done
export PATH="$PATH:/usr/sbin"
ctld_port="${3:-16817}"
slurmd_port="${4:-16818}"
mkdir -p "$dir"
dir="$(cd "$dir" && pwd)"
mkdir -p "$dir/munge" "$dir/spool/ctld" "$dir/spool/d" "$dir/log"
chmod 700 "$dir/munge"
# munged wants every directory above its socket searchable by all (DIR may
# be a private temporary directory), so the socket lives in /tmp.
sock_dir="$(mktemp -d /tmp/campanile-munge.XXXXXX)"
chmod 755 "$sock_dir"
echo "$sock_dir" > "$dir/munge/socket-dir"
user="$(id -un)"
host="$(hostname -s)"
# A key of our own, so that a non-root user can run munged.
[ -f "$dir/munge/munge.key" ] || { head -c 1024 /dev/urandom > "$dir/munge/munge.key"; chmod 400 "$dir/munge/munge.key"; }
force=()
[ "$(id -u)" -eq 0 ] && force=(--force)
munged "${force[@]}" --socket="$sock_dir/munge.socket" --key-file="$dir/munge/munge.key" \
    --pid-file="$dir/munge/munged.pid" --log-file="$dir/munge/munged.log" --seed-file="$dir/munge/munged.seed"
cat > "$dir/slurm.conf" <<CONF
# one-node.sh: a one-node cluster for tests ($(date -u +%FT%TZ))
ClusterName=campanile-one-node
SlurmctldHost=$host(127.0.0.1)
AuthType=auth/munge
AuthInfo=socket=$sock_dir/munge.socket
CredType=cred/munge
SlurmUser=$user
SlurmdUser=$user
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
StateSaveLocation=$dir/spool/ctld
SlurmdSpoolDir=$dir/spool/d
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
ReturnToService=2
MinJobAge=3600
MpiDefault=none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
NodeName=$host NodeAddr=127.0.0.1 CPUs=$(nproc) State=UNKNOWN
PartitionName=one Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$dir/slurm.conf"
slurmctld
slurmd
for _ in $(seq 60); do
    if sinfo -h -o '%T' 2>/dev/null | grep -qx idle; then
        echo "export SLURM_CONF=$dir/slurm.conf"
        exit 0
    fi
    sleep 0.5
done
echo "one-node.sh: the node did not come up idle in 30 s; sinfo says: $(sinfo -h 2>&1)" >&2
tail -n 20 "$dir/log/slurmctld.log" "$dir/log/slurmd.log" "$dir/munge/munged.log" >&2 2>/dev/null || true
stop
exit 1
