#!/usr/bin/env bash
# Starts a single-node Slurm cluster on 127.0.0.1 (munge, slurmctld,
# slurmd; no systemd, no cgroups) for trying `tet-bench submit --engine
# slurm` and for the Slurm integration test. Debian/Ubuntu, as root.
#
#   scripts/slurm/single-node.sh            # install if missing, start, wait for the node
#   export SLURM_CONF=/tmp/tet-slurm/slurm.conf
#   sinfo                                   # one node, idle
#   scripts/slurm/stop.sh                   # stop the daemons
#
# Everything lives in $TET_SLURM_DIR (default /tmp/tet-slurm): slurm.conf,
# state, spool, logs and pid files. /etc/slurm/slurm.conf is written only
# when absent (a symlink to ours), so plain `sinfo` works too; an existing
# configuration is left alone and SLURM_CONF must then be set.
set -euo pipefail

DIR=${TET_SLURM_DIR:-/tmp/tet-slurm}
WAIT_S=${TET_SLURM_WAIT_S:-60}

say() { echo "single-node.sh: $*" >&2; }

if [ "$(id -u)" != 0 ]; then
    say "run as root (it installs packages and starts daemons)"
    exit 1
fi

# 1. Packages, only when missing.
missing=()
for bin in munged:munge slurmctld:slurmctld slurmd:slurmd sbatch:slurm-client; do
    command -v "${bin%%:*}" >/dev/null 2>&1 || missing+=("${bin##*:}")
done
if [ ${#missing[@]} -gt 0 ]; then
    say "installing ${missing[*]}"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    # Keep the packages' own service starts out (there is no systemd here).
    apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# 2. Munge: a key, a socket directory, the daemon as the munge user.
if [ ! -s /etc/munge/munge.key ]; then
    if command -v mungekey >/dev/null 2>&1; then
        mungekey --create --keyfile=/etc/munge/munge.key
    else
        dd if=/dev/urandom of=/etc/munge/munge.key bs=1024 count=1 status=none
    fi
fi
chown munge:munge /etc/munge/munge.key
chmod 400 /etc/munge/munge.key
install -d -o munge -g munge -m 0755 /run/munge /var/log/munge /var/lib/munge
if ! munge -n </dev/null 2>/dev/null | unmunge >/dev/null 2>&1; then
    say "starting munged"
    runuser -u munge -- /usr/sbin/munged
    mkdir -p "$DIR"
    echo /run/munge/munged.pid >"$DIR/munged.started"
    for _ in $(seq 50); do
        munge -n </dev/null 2>/dev/null | unmunge >/dev/null 2>&1 && break
        sleep 0.1
    done
fi
munge -n </dev/null | unmunge >/dev/null

# 3. slurm.conf: this host on 127.0.0.1, its CPUs and memory.
mkdir -p "$DIR/state" "$DIR/spool" "$DIR/log"
HOST=$(hostname -s)
CPUS=$(nproc)
MEM_MB=$(awk '/^MemTotal:/ { print int($2 / 1024) }' /proc/meminfo)
CONF="$DIR/slurm.conf"
cat >"$CONF.tmp" <<CONF
# Written by scripts/slurm/single-node.sh: one node on 127.0.0.1.
ClusterName=tet
SlurmctldHost=$HOST(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
StateSaveLocation=$DIR/state
SlurmdSpoolDir=$DIR/spool
SlurmctldPidFile=$DIR/slurmctld.pid
SlurmdPidFile=$DIR/slurmd.pid
SlurmctldLogFile=$DIR/log/slurmctld.log
SlurmdLogFile=$DIR/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
SchedulerType=sched/backfill
MpiDefault=none
ReturnToService=2
SlurmdTimeout=300
InactiveLimit=0
MinJobAge=300
KillWait=5
NodeName=$HOST NodeAddr=127.0.0.1 CPUs=$CPUS RealMemory=$MEM_MB State=UNKNOWN
PartitionName=debug Nodes=$HOST Default=YES MaxTime=INFINITE State=UP
CONF
mv "$CONF.tmp" "$CONF"
export SLURM_CONF="$CONF"
mkdir -p /etc/slurm
if [ ! -e /etc/slurm/slurm.conf ] || [ "$(readlink /etc/slurm/slurm.conf)" = "$CONF" ]; then
    ln -sfn "$CONF" /etc/slurm/slurm.conf
fi

# 4. The daemons (running ones with the same pid files are kept).
alive() { [ -s "$1" ] && kill -0 "$(cat "$1")" 2>/dev/null; }
if ! alive "$DIR/slurmctld.pid"; then
    say "starting slurmctld"
    slurmctld -f "$CONF"
fi
if ! alive "$DIR/slurmd.pid"; then
    say "starting slurmd"
    slurmd -f "$CONF"
fi

# 5. Wait until the node is idle.
for _ in $(seq $((WAIT_S * 2))); do
    state=$(sinfo -h -N -n "$HOST" -o '%T' 2>/dev/null || true)
    case "$state" in
    idle*)
        say "node $HOST idle ($CPUS CPUs, $MEM_MB MB); export SLURM_CONF=$CONF"
        exit 0
        ;;
    esac
    sleep 0.5
done
say "node $HOST not idle after ${WAIT_S}s (state: ${state:-none}); logs in $DIR/log"
tail -n 20 "$DIR/log/slurmctld.log" "$DIR/log/slurmd.log" >&2 || true
exit 1
