#!/usr/bin/env bash
# A single-node Slurm on this machine, for running sweeps through the same scheduler clusters
# use (`depotwin sweep FILE --emit slurm`). Needs root and the Debian packages slurmctld,
# slurmd, slurm-client and munge (scripts/setup.sh installs them).
#
#   scripts/slurm-local.sh start    # munge key, slurm.conf for this host, munged + slurmctld + slurmd
#   scripts/slurm-local.sh status   # exit 0 when the node takes jobs
#   scripts/slurm-local.sh stop     # stops what `start` started
#
# The configuration goes to /etc/slurm/slurm.conf (where sbatch and squeue look), but only when
# that file is absent or was written by this script; daemons' state, logs and pid files live in
# $DEPOTWIN_SLURM_DIR (default /var/tmp/depotwin-slurm). One partition, `local`, holds this
# host with all its cores; no accounting, no cgroups. Every step waits at most
# $DEPOTWIN_SLURM_TIMEOUT_S seconds (default 30), so a machine where Slurm cannot start fails
# fast with the reason.
set -euo pipefail

state_dir="${DEPOTWIN_SLURM_DIR:-/var/tmp/depotwin-slurm}"
timeout_s="${DEPOTWIN_SLURM_TIMEOUT_S:-30}"
conf=/etc/slurm/slurm.conf
marker="# written by depotwin scripts/slurm-local.sh"
munge_pid=/run/munge/munged.pid

say() { echo "slurm-local: $*"; }
fail() { echo "slurm-local: $*" >&2; exit 1; }

# true when the node answers and takes jobs
node_ready() {
  local state
  state=$(timeout 5 sinfo -h -N -o '%T' 2>/dev/null | head -n1) || return 1
  case "$state" in idle* | mixed* | allocated* | completing*) return 0 ;; *) return 1 ;; esac
}

# wait up to timeout_s for a command to succeed
wait_for() {
  local what="$1"
  shift
  local waited=0
  until "$@"; do
    if [ "$waited" -ge "$timeout_s" ]; then return 1; fi
    sleep 1
    waited=$((waited + 1))
  done
  say "$what after ${waited} s"
}

# a pid file's process, when it runs
running_pid() {
  local file="$1" pid
  [ -r "$file" ] || return 1
  pid=$(cat "$file" 2>/dev/null) || return 1
  [ -n "$pid" ] && kill -0 "$pid" 2>/dev/null && echo "$pid"
}

start() {
  [ "$(id -u)" -eq 0 ] || fail "needs root (slurmd starts jobs as their users; munged needs its key)"
  for program in munged slurmctld slurmd sbatch squeue sinfo scontrol; do
    command -v "$program" >/dev/null ||
      fail "$program not found: install slurmctld slurmd slurm-client munge (scripts/setup.sh)"
  done
  if node_ready; then
    say "already running: $(sinfo -h -N -o '%N %c cores %T')"
    return 0
  fi
  mkdir -p "$state_dir/slurmctld" "$state_dir/slurmd"

  # munge: a key, then the daemon (as its own user)
  if [ ! -s /etc/munge/munge.key ]; then
    say "creating /etc/munge/munge.key"
    mungekey --create --keyfile=/etc/munge/munge.key 2>/dev/null ||
      dd if=/dev/urandom bs=1 count=1024 of=/etc/munge/munge.key status=none
    chown munge:munge /etc/munge/munge.key
    chmod 400 /etc/munge/munge.key
  fi
  mkdir -p /run/munge /var/log/munge /var/lib/munge
  chown munge:munge /run/munge /var/log/munge /var/lib/munge
  if ! running_pid "$munge_pid" >/dev/null; then
    runuser -u munge -- /usr/sbin/munged || fail "munged did not start (see /var/log/munge/munged.log)"
  fi
  wait_for "munge answers" sh -c 'munge -n | unmunge >/dev/null 2>&1' ||
    fail "munge does not answer within ${timeout_s} s"

  # slurm.conf for this host and its cores
  if [ -e "$conf" ] && ! grep -qF "$marker" "$conf"; then
    fail "$conf exists and was not written by this script; leaving it alone (a Slurm of your own?)"
  fi
  local host cpus memory
  host=$(hostname -s)
  cpus=$(nproc)
  memory=$(slurmd -C 2>/dev/null | sed -n 's/.*RealMemory=\([0-9]*\).*/\1/p')
  mkdir -p /etc/slurm
  cat >"$conf" <<EOF
$marker: a single-node Slurm on $host
ClusterName=depotwin-local
SlurmctldHost=$host
SlurmUser=root
AuthType=auth/munge
CryptoType=crypto/munge
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
SlurmctldPidFile=$state_dir/slurmctld.pid
SlurmdPidFile=$state_dir/slurmd.pid
StateSaveLocation=$state_dir/slurmctld
SlurmdSpoolDir=$state_dir/slurmd
SlurmctldLogFile=$state_dir/slurmctld.log
SlurmdLogFile=$state_dir/slurmd.log
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=${memory:-1000} State=UNKNOWN
PartitionName=local Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
  say "wrote $conf: node $host, $cpus cores"

  # the controller, then the node daemon
  running_pid "$state_dir/slurmctld.pid" >/dev/null || slurmctld ||
    fail "slurmctld did not start (see $state_dir/slurmctld.log)"
  running_pid "$state_dir/slurmd.pid" >/dev/null || slurmd ||
    fail "slurmd did not start (see $state_dir/slurmd.log)"
  if ! wait_for "node ready" node_ready; then
    # a node left down by an earlier run comes back
    scontrol update nodename="$host" state=resume >/dev/null 2>&1 || true
    wait_for "node ready" node_ready ||
      fail "the node is not ready within ${timeout_s} s: $(sinfo -h -N -o '%N %T %E' 2>&1); see $state_dir/*.log"
  fi
  say "running: $(sinfo -h -N -o '%N, %c cores, %T'); submit with sbatch, watch with squeue"
}

stop() {
  local pid
  # the daemons this script started, by their pid files
  for daemon in slurmd slurmctld; do
    if pid=$(running_pid "$state_dir/$daemon.pid"); then
      kill "$pid"
      say "stopped $daemon ($pid)"
    fi
  done
  if [ -e "$conf" ] && grep -qF "$marker" "$conf" && pid=$(running_pid "$munge_pid"); then
    kill "$pid"
    say "stopped munged ($pid)"
  fi
}

case "${1:-}" in
  start) start ;;
  stop) stop ;;
  status)
    if node_ready; then
      say "running: $(sinfo -h -N -o '%N, %c cores, %T')"
    else
      say "not running"
      exit 1
    fi
    ;;
  *)
    echo "usage: $0 start|status|stop" >&2
    exit 2
    ;;
esac
