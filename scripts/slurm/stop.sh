#!/usr/bin/env bash
# Stop the daemons started by scripts/slurm/start.sh (slurmd, slurmctld, munged).
set -u
for pidfile in /run/slurmd.pid /run/slurmctld.pid /run/munge/munged.pid; do
    [[ -s $pidfile ]] && kill "$(cat "$pidfile")" 2>/dev/null
done
exit 0
