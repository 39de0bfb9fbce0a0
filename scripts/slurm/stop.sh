#!/usr/bin/env bash
# Stops what scripts/slurm/single-node.sh started (slurmd, slurmctld, and
# munged when it started it), by their pid files. State and logs stay in
# $TET_SLURM_DIR (default /tmp/tet-slurm); `--purge` removes them.
set -euo pipefail

DIR=${TET_SLURM_DIR:-/tmp/tet-slurm}

stop() {
    local pidfile=$1 name=$2
    [ -s "$pidfile" ] || return 0
    local pid
    pid=$(cat "$pidfile")
    if kill -0 "$pid" 2>/dev/null; then
        kill "$pid"
        for _ in $(seq 100); do
            kill -0 "$pid" 2>/dev/null || break
            sleep 0.1
        done
        if kill -0 "$pid" 2>/dev/null; then
            kill -9 "$pid" 2>/dev/null || true
        fi
        echo "stop.sh: stopped $name ($pid)" >&2
    fi
    rm -f "$pidfile"
}

stop "$DIR/slurmd.pid" slurmd
stop "$DIR/slurmctld.pid" slurmctld
if [ -s "$DIR/munged.started" ]; then
    stop "$(cat "$DIR/munged.started")" munged
    rm -f "$DIR/munged.started"
fi
if [ -e /etc/slurm/slurm.conf ] && [ "$(readlink /etc/slurm/slurm.conf)" = "$DIR/slurm.conf" ]; then
    rm -f /etc/slurm/slurm.conf
fi
if [ "${1:-}" = --purge ]; then
    rm -rf "$DIR"
fi
