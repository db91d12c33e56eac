#!/usr/bin/env bash
# A one-node SLURM cluster on this machine, for the launcher tests and for trying
# `hydra/launcher=slurm` without a cluster. Root on Debian (installs slurm-wlm and munge).
#   bash scripts/slurm_local.sh start    # install if needed, configure, start, wait until idle
#   bash scripts/slurm_local.sh status   # sinfo
#   bash scripts/slurm_local.sh stop
# Accounting storage stays off; job completions go to a text file so `sacct`-like states are
# readable (JobCompType=jobcomp/filetxt, $STATE/jobcomp.txt).
set -euo pipefail

STATE=${SLURM_LOCAL_STATE:-/var/lib/lca-slurm}
CONF=/etc/slurm/slurm.conf
WAIT_S=${SLURM_LOCAL_WAIT_S:-60}

install() {
  if command -v slurmctld >/dev/null && command -v munged >/dev/null; then return; fi
  [ "$(id -u)" = 0 ] || { echo "slurm_local: needs root to install slurm-wlm and munge" >&2; exit 1; }
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends slurm-wlm munge >/dev/null
}

configure() {
  local host cpus mem
  host=$(hostname -s)
  cpus=$(nproc)
  mem=$(( $(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 - 1024 ))  # MB, 1 GB for the OS
  mkdir -p "$STATE" /etc/slurm /var/log/slurm /var/spool/slurmd /var/spool/slurmctld /run/munge
  cat >"$CONF" <<CONF
ClusterName=lca-local
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
StateSaveLocation=/var/spool/slurmctld
SlurmdSpoolDir=/var/spool/slurmd
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
ReturnToService=2
JobRequeue=1
# a requeued or cancelled job gets SIGTERM, then SIGKILL this many seconds later (default 30)
KillWait=5
JobCompType=jobcomp/filetxt
JobCompLoc=$STATE/jobcomp.txt
SlurmctldLogFile=/var/log/slurm/slurmctld.log
SlurmdLogFile=/var/log/slurm/slurmd.log
SlurmctldPidFile=/run/slurmctld.pid
SlurmdPidFile=/run/slurmd.pid
NodeName=$host CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=local Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
  if [ ! -s /etc/munge/munge.key ]; then
    mkdir -p /etc/munge
    dd if=/dev/urandom bs=1 count=1024 of=/etc/munge/munge.key 2>/dev/null
  fi
  chown -R munge:munge /etc/munge /run/munge /var/lib/munge /var/log/munge 2>/dev/null || true
  chmod 400 /etc/munge/munge.key
}

# a live process of this name (a daemon killed hard can linger as a zombie: not running)
running() {
  ps -C "$1" -o stat= 2>/dev/null | grep -qv '^Z'
}

start() {
  install
  configure
  running munged || su -s /bin/sh munge -c "/usr/sbin/munged --force"
  running slurmctld || slurmctld
  running slurmd || slurmd
  local began=$SECONDS waited=0
  until timeout 5 sinfo -h -o %T 2>/dev/null | grep -q idle; do
    waited=$((SECONDS - began))
    if [ "$waited" -ge "$WAIT_S" ]; then
      echo "slurm_local: the node is not idle after ${WAIT_S} s:" >&2
      sinfo >&2 || true
      tail -n 20 /var/log/slurm/slurmctld.log /var/log/slurm/slurmd.log >&2 || true
      exit 1
    fi
    sleep 1
    # a node left DOWN or DRAINED by an earlier run comes back
    timeout 5 scontrol update nodename="$(hostname -s)" state=resume >/dev/null 2>&1 || true
  done
  echo "slurm_local: node $(hostname -s) idle after $((SECONDS - began)) s ($(nproc) CPUs)"
}

stop() {
  local name waited
  for name in slurmd slurmctld munged; do
    pkill -x "$name" || true
    waited=0  # gone before a later start looks for it
    while running "$name" && [ "$waited" -lt 20 ]; do
      sleep 0.5
      waited=$((waited + 1))
    done
  done
}

case "${1:-}" in
  start) start ;;
  stop) stop ;;
  status) sinfo ;;
  *) echo "usage: $0 start|stop|status" >&2; exit 2 ;;
esac
