#!/usr/bin/env bash
# A one-node Slurm cluster on this machine, for the farm tests and `scripts/bench.sh farm`: munged,
# slurmctld and slurmd on localhost, one partition `local` with this machine's cores and memory.
# Needs root and Debian's slurm-wlm and munge (scripts/setup.sh installs them).
#   scripts/slurm-local.sh start    bring it up (idempotent); exit 0 when sinfo shows the node idle
#   scripts/slurm-local.sh stop     stop what `start` started and remove its config
#   scripts/slurm-local.sh status   exit 0 when it is up
# `start` exits 77 (the test suite's "skipped") with the reason on stderr when it cannot: not root, Slurm
# not installed, or a slurm.conf it did not write already in place (a real cluster: left alone).
# State, logs and the config live in $HAIRGEN_SLURM_DIR (default /tmp/hairgen-slurm); the config is
# also linked as /etc/slurm/slurm.conf so sbatch, squeue and scancel find it.
set -euo pipefail
state=${HAIRGEN_SLURM_DIR:-/tmp/hairgen-slurm}
conf=/etc/slurm/slurm.conf
marker="# written by hairgen scripts/slurm-local.sh"
skip() { echo "slurm-local: cannot start a local Slurm: $*" >&2; exit 77; }

up() { sinfo --noheader --nodes=localhost --format=%T 2>/dev/null | grep -qE '^(idle|mixed|allocated)'; }

start() {
  [ "$(id -u)" -eq 0 ] || skip "not root (munged, slurmctld and slurmd run as root here)"
  for tool in munged munge slurmctld slurmd sbatch squeue sinfo scontrol; do
    command -v "$tool" >/dev/null 2>&1 || [ -x "/usr/sbin/$tool" ] || skip "$tool is not installed (apt-get install slurm-wlm munge)"
  done
  export PATH="$PATH:/usr/sbin"
  if [ -e "$conf" ] && ! grep -qF "$marker" "$conf"; then skip "$conf exists and is not ours (a real cluster?)"; fi
  if up; then echo "slurm-local: already up"; return 0; fi
  mkdir -p "$state/ctld" "$state/d"

  # munge: a key, its run folder, the daemon (as the munge user where there is one).
  if ! munge -n 2>/dev/null | unmunge >/dev/null 2>&1; then
    if [ ! -s /etc/munge/munge.key ]; then
      mkdir -p /etc/munge
      dd if=/dev/urandom of=/etc/munge/munge.key bs=1 count=1024 status=none
    fi
    mkdir -p /run/munge /var/log/munge /var/lib/munge
    if id munge >/dev/null 2>&1; then
      chown munge:munge /etc/munge /etc/munge/munge.key /run/munge /var/log/munge /var/lib/munge
      chmod 0400 /etc/munge/munge.key
      runuser -u munge -- munged
    else
      chmod 0400 /etc/munge/munge.key
      munged --force
    fi
    touch "$state/munged.started"
    for _ in $(seq 50); do munge -n 2>/dev/null | unmunge >/dev/null 2>&1 && break; sleep 0.1; done
    munge -n | unmunge >/dev/null 2>&1 || skip "munged did not start"
  fi

  # This machine's cores and memory, less a little for the system.
  cpus=$(nproc)
  mem=$(awk '/MemTotal/ { printf "%d", $2 / 1024 * 0.9 }' /proc/meminfo)
  mkdir -p /etc/slurm
  cat > "$state/slurm.conf" <<CONF
$marker
ClusterName=hairgen
SlurmctldHost=localhost
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
StateSaveLocation=$state/ctld
SlurmdSpoolDir=$state/d
SlurmctldPidFile=$state/slurmctld.pid
SlurmdPidFile=$state/slurmd.pid
SlurmctldLogFile=$state/slurmctld.log
SlurmdLogFile=$state/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU_Memory
DependencyParameters=kill_invalid_depend
ReturnToService=2
MinJobAge=600
DefMemPerCPU=1024
NodeName=localhost NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=local Nodes=localhost Default=YES MaxTime=INFINITE State=UP
CONF
  cp "$state/slurm.conf" "$conf"
  slurmctld -f "$conf" || skip "slurmctld did not start (see $state/slurmctld.log)"
  slurmd -f "$conf" -N localhost || skip "slurmd did not start (see $state/slurmd.log)"
  for _ in $(seq 100); do up && break; sleep 0.2; done
  if ! up; then
    scontrol update nodename=localhost state=resume >/dev/null 2>&1 || true
    for _ in $(seq 50); do up && break; sleep 0.2; done
  fi
  up || skip "the node did not come up: $(sinfo --noheader 2>&1 | head -3) (see $state/slurmd.log)"
  echo "slurm-local: up, one node with $cpus CPUs and $mem MiB (partition local)"
}

stop() {
  for daemon in slurmd slurmctld; do
    pidfile="$state/$daemon.pid"
    if [ -s "$pidfile" ]; then
      pid=$(cat "$pidfile")
      kill "$pid" 2>/dev/null || true
      for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
      rm -f "$pidfile"
    fi
  done
  if [ -e "$state/munged.started" ] && [ -s /run/munge/munged.pid ]; then
    kill "$(cat /run/munge/munged.pid)" 2>/dev/null || true
    rm -f "$state/munged.started"
  fi
  if [ -e "$conf" ] && grep -qF "$marker" "$conf"; then rm -f "$conf"; fi
  rm -rf "$state"
  echo "slurm-local: stopped"
}

case "${1:-}" in
start) start ;;
stop) stop ;;
status) up ;;
*) echo "usage: $0 start|stop|status" >&2; exit 2 ;;
esac
