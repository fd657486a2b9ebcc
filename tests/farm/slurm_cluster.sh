#!/usr/bin/env bash
# slurm_cluster.sh start DIR | stop DIR: a one-node Slurm cluster on this machine for the farm tests
# (munged, slurmctld, slurmd; loopback only; state, logs and slurm.conf in DIR). `start` prints the
# SLURM_CONF to export; exits 77 (ctest: skipped) with a message where Slurm cannot run here (not root,
# packages missing, daemons refusing to start).
set -uo pipefail
action=$1 dir=$2
skip() { echo "skipped: $*" >&2; exit 77; }

stop() {
  for daemon in slurmd slurmctld; do
    [[ -f "$dir/$daemon.pid" ]] && kill "$(cat "$dir/$daemon.pid")" 2>/dev/null
  done
  sleep 1
  for daemon in slurmd slurmctld; do
    [[ -f "$dir/$daemon.pid" ]] && kill -9 "$(cat "$dir/$daemon.pid")" 2>/dev/null
    rm -f "$dir/$daemon.pid"
  done
  pkill -9 -f -- "-f $dir/slurm.conf" 2>/dev/null  # any that had not written its pid file yet
  # munged too, if this script started it.
  if [[ -f "$dir/munged.started" ]]; then pkill -x munged; rm -f "$dir/munged.started"; fi
  return 0
}

if [[ $action == stop ]]; then stop; exit 0; fi

[[ $(id -u) -eq 0 ]] || skip "the Slurm test cluster needs root (slurmd runs jobs as their user)"
for tool in munged munge unmunge slurmctld slurmd sbatch squeue scancel sinfo; do
  command -v "$tool" >/dev/null || skip "$tool not installed (Debian packages slurm-wlm and munge; make deps installs them)"
done
mkdir -p "$dir/state" "$dir/spool" "$dir/log"
host=$(hostname -s)
cpus=$(nproc)
mem=$(( $(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 / 2 ))
cat > "$dir/slurm.conf" <<CONF
ClusterName=facetfit-test
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
SlurmctldPort=16817
SlurmdPort=16818
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
MinJobAge=600
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=test Nodes=$host Default=YES MaxTime=INFINITE State=UP OverSubscribe=YES
CONF
export SLURM_CONF=$dir/slurm.conf
# munge: the packaged key, a daemon if none is running.
munge_works() { munge -n 2>/dev/null | unmunge >/dev/null 2>&1; }
if ! munge_works; then  # (a process list may show a dead munged: ask it instead)
  [[ -f /etc/munge/munge.key ]] || skip "no /etc/munge/munge.key"
  mkdir -p /run/munge && chown munge:munge /run/munge 2>/dev/null
  /usr/sbin/munged --force >"$dir/log/munged.log" 2>&1 || skip "munged does not start: $(tail -1 "$dir/log/munged.log")"
  touch "$dir/munged.started"
fi
for _ in $(seq 1 50); do  # munged answers a moment after it forks
  munge_works && break
  sleep 0.2
done
munge_works || { stop; skip "munged does not answer"; }
slurmctld -c -f "$SLURM_CONF" >"$dir/log/start.log" 2>&1 || { stop; skip "slurmctld does not start: $(tail -1 "$dir/log/start.log")"; }
slurmd -f "$SLURM_CONF" >>"$dir/log/start.log" 2>&1 || { stop; skip "slurmd does not start: $(tail -1 "$dir/log/start.log")"; }
for _ in $(seq 1 30); do
  if sinfo -h -o %T 2>/dev/null | grep -qE '^(idle|mixed|allocated)'; then echo "$SLURM_CONF"; exit 0; fi
  sleep 1
done
stop
skip "the Slurm node did not come up in 30 s ($(sinfo -h -o %T 2>&1 | head -1)); logs in $dir/log"
