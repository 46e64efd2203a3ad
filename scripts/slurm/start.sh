#!/usr/bin/env bash
# Start a single-node Slurm cluster on this machine (Debian's munge, slurmctld, slurmd),
# for running the workflow with `snakemake --executor slurm` (workflow/profiles/slurm).
#
#   sudo scripts/slurm/start.sh            # needs root; installs nothing unless --install
#   sudo scripts/slurm/start.sh --install  # apt-get install -y slurmctld slurmd munge slurm-client first
#   scripts/slurm/stop.sh                   # stop the daemons
#
# The configuration (/etc/slurm/slurm.conf, written only if absent or written by this
# script) is minimal: this host as the controller and the one compute node with all its
# CPUs, select/cons_tres on cores, proctrack/linuxproc and task/none (no cgroups), no
# accounting database (AccountingStorageType=accounting_storage/none): the Snakemake
# plugin then asks `squeue` for job states (status_command: squeue in the profile), which
# is its documented alternative to sacct when finished jobs stay visible for MinJobAge
# (300 s here, above the plugin's threshold of 3 x the first status-check interval).
set -euo pipefail

if [[ "${1:-}" == "--install" ]]; then
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq slurmctld slurmd munge slurm-client
fi
for cmd in munged slurmctld slurmd sinfo sbatch; do
    command -v "$cmd" > /dev/null || { echo "start.sh: $cmd not found (run with --install)" >&2; exit 2; }
done
[[ $(id -u) == 0 ]] || { echo "start.sh: run as root" >&2; exit 2; }

MARK="# written by ncd scripts/slurm/start.sh"
CONF=/etc/slurm/slurm.conf
HOST=$(hostname -s)
CPUS=$(nproc)
MEM=$(( $(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 * 9 / 10 ))
if [[ -e $CONF ]] && ! grep -q "^$MARK" "$CONF"; then
    echo "start.sh: $CONF exists and was not written by this script: using it as it is" >&2
else
    mkdir -p /etc/slurm
    cat > "$CONF" <<CONF
$MARK
ClusterName=ncd
SlurmctldHost=$HOST
SlurmUser=root
AuthType=auth/munge
CredType=cred/munge
MpiDefault=none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
ReturnToService=2
MinJobAge=300
SchedulerType=sched/backfill
StateSaveLocation=/var/spool/slurmctld
SlurmdSpoolDir=/var/spool/slurmd
SlurmctldPidFile=/run/slurmctld.pid
SlurmdPidFile=/run/slurmd.pid
SlurmctldLogFile=/var/log/slurm/slurmctld.log
SlurmdLogFile=/var/log/slurm/slurmd.log
NodeName=$HOST NodeAddr=127.0.0.1 CPUs=$CPUS RealMemory=$MEM State=UNKNOWN
PartitionName=main Nodes=$HOST Default=YES MaxTime=INFINITE State=UP
CONF
fi
mkdir -p /var/spool/slurmctld /var/spool/slurmd /var/log/slurm /run/munge
chown munge:munge /run/munge 2>/dev/null || true

# munge: the key comes with the Debian package; start the daemon unless it answers
if ! munge -n 2>/dev/null | unmunge > /dev/null 2>&1; then
    [[ -s /etc/munge/munge.key ]] || { mungekey --create 2>/dev/null || /usr/sbin/create-munge-key -f; }
    chown munge:munge /etc/munge/munge.key && chmod 400 /etc/munge/munge.key
    runuser -u munge -- /usr/sbin/munged
    for _ in $(seq 50); do munge -n 2>/dev/null | unmunge > /dev/null 2>&1 && break; sleep 0.1; done
fi
munge -n | unmunge > /dev/null || { echo "start.sh: munge does not answer" >&2; exit 1; }

# the controller and the node daemon (each once)
pidof slurmctld > /dev/null || slurmctld
pidof slurmd > /dev/null || slurmd
for _ in $(seq 100); do
    state=$(sinfo -h -N -o '%t' 2>/dev/null | head -1 || true)
    [[ "$state" == idle* || "$state" == mix* || "$state" == alloc* ]] && break
    sleep 0.2
done
state=$(sinfo -h -N -o '%t' 2>/dev/null | head -1 || true)
if [[ "$state" != idle* && "$state" != mix* && "$state" != alloc* ]]; then
    scontrol update nodename="$HOST" state=resume 2>/dev/null || true
    sleep 1
    state=$(sinfo -h -N -o '%t' 2>/dev/null | head -1 || true)
fi
sinfo
[[ "$state" == idle* || "$state" == mix* || "$state" == alloc* ]] || {
    echo "start.sh: node $HOST is '$state'; see /var/log/slurm/slurmctld.log and slurmd.log" >&2; exit 1; }
echo "start.sh: Slurm is up on $HOST ($CPUS CPUs, ${MEM} MB)"
