#!/usr/bin/env bash
# ci/slurm_setup.sh — a single-node Slurm cluster on this machine, for the scale-out test
# (ci/cluster_test.sh, ctest label `cluster`; REQ-REPORT-007).
#
#   bash ci/slurm_setup.sh            # install, configure and start munged, slurmctld, slurmd
#   bash ci/slurm_setup.sh --stop     # stop the three daemons (packages and config stay)
#   bash ci/slurm_setup.sh --status   # show the daemons and sinfo
#
# Idempotent: installs only missing Debian (bookworm) packages (slurm-wlm, munge, and GNU
# parallel with rsync, which its --return needs), rewrites /etc/slurm/slurm.conf only when
# it changes (and then restarts the daemons), creates the munge key only if it is missing,
# starts only daemons that are not running, and waits until `sinfo` shows the node idle.
# There is no systemd here: the daemons are started directly and stopped by their pid files
# (/run/munge/munged.pid, /run/slurmctld.pid, /run/slurmd.pid). Needs root (or sudo).
set -euo pipefail

if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then exec sudo -n bash "$0" "$@"; fi
  echo "ci/slurm_setup.sh: needs root or sudo" >&2; exit 1
fi

say() { echo "ci/slurm_setup.sh: $*"; }
die() { echo "ci/slurm_setup.sh: error: $*" >&2; exit 1; }

CONF=/etc/slurm/slurm.conf
PIDS=(/run/slurmd.pid /run/slurmctld.pid /run/munge/munged.pid)

alive() {  # alive PIDFILE: the daemon named in PIDFILE runs (not another process with a reused pid)
  local pid name
  [ -s "$1" ] || return 1
  pid=$(cat "$1"); name=$(basename "$1" .pid)
  [ "$(cat /proc/"$pid"/comm 2>/dev/null)" = "$name" ]
}

stop_daemons() {
  local f pid
  for f in "${PIDS[@]}"; do
    if alive "$f"; then
      pid=$(cat "$f")
      say "stopping $(basename "$f" .pid) ($pid)"
      kill "$pid"
      for _ in $(seq 1 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.2; done
      if kill -0 "$pid" 2>/dev/null; then say "pid $pid ignored SIGTERM; SIGKILL"; kill -9 "$pid" || true; fi
    fi
    rm -f "$f"
  done
}

case "${1:-}" in
  --stop) stop_daemons; say "stopped"; exit 0 ;;
  --status)
    for f in "${PIDS[@]}"; do
      if alive "$f"; then echo "$f: running ($(cat "$f"))"; else echo "$f: not running"; fi
    done
    sinfo 2>&1 || true
    exit 0 ;;
  "") ;;
  *) echo "usage: $0 [--stop|--status]" >&2; exit 2 ;;
esac

# 1. Packages.
PACKAGES=(slurm-wlm munge parallel rsync)
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ "${#missing[@]}" -gt 0 ]; then
  say "installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  # Keep the packages' maintainer scripts from starting daemons: we start them below.
  own_policy=""
  if [ ! -e /usr/sbin/policy-rc.d ]; then
    printf '#!/bin/sh\nexit 101\n' > /usr/sbin/policy-rc.d; chmod +x /usr/sbin/policy-rc.d; own_policy=1
  fi
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}"
  [ -n "$own_policy" ] && rm -f /usr/sbin/policy-rc.d
else
  say "packages already installed (${PACKAGES[*]})"
fi

# 2. Munge key (the package's postinst usually made one).
install -d -o munge -g munge -m 0700 /etc/munge /var/lib/munge /var/log/munge
install -d -o munge -g munge -m 0755 /run/munge
if [ ! -s /etc/munge/munge.key ]; then
  say "creating /etc/munge/munge.key"
  if command -v mungekey >/dev/null 2>&1; then mungekey --create --keyfile=/etc/munge/munge.key --force
  else dd if=/dev/urandom of=/etc/munge/munge.key bs=1 count=1024 status=none; fi
fi
chown munge:munge /etc/munge/munge.key; chmod 0400 /etc/munge/munge.key

# 3. slurm.conf for this one node.
host=$(hostname -s)
node=$(slurmd -C | head -n 1)   # NodeName=<host> CPUs=... RealMemory=...
case "$node" in NodeName=*) ;; *) die "slurmd -C printed no NodeName line: $node" ;; esac
node="NodeName=$host ${node#NodeName=* }"
install -d -o slurm -g slurm -m 0755 /var/spool/slurmctld /var/spool/slurmd /var/log/slurm
new=$(cat <<EOF
# Written by ci/slurm_setup.sh: a single-node cluster for MINER's scale-out test.
ClusterName=miner
SlurmctldHost=$host
SlurmUser=slurm
AuthType=auth/munge
CryptoType=crypto/munge
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SwitchType=switch/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
SlurmctldPidFile=/run/slurmctld.pid
SlurmdPidFile=/run/slurmd.pid
StateSaveLocation=/var/spool/slurmctld
SlurmdSpoolDir=/var/spool/slurmd
SlurmctldLogFile=/var/log/slurm/slurmctld.log
SlurmdLogFile=/var/log/slurm/slurmd.log
SlurmctldTimeout=30
SlurmdTimeout=60
InactiveLimit=0
MinJobAge=300
KillWait=10
Waittime=0
$node State=UNKNOWN
PartitionName=main Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
)
restart=""
if [ ! -f "$CONF" ] || [ "$(cat "$CONF")" != "$new" ]; then
  say "writing $CONF ($node)"
  printf '%s\n' "$new" > "$CONF"
  restart=1
fi
[ -n "$restart" ] && stop_daemons

# 4. Daemons (each one daemonises itself and writes its pid file).
if ! alive /run/munge/munged.pid; then
  say "starting munged"
  runuser -u munge -- /usr/sbin/munged
fi
for _ in $(seq 1 50); do munge -n </dev/null | unmunge >/dev/null 2>&1 && break; sleep 0.2; done
munge -n </dev/null | unmunge >/dev/null || die "munge does not work (see /var/log/munge/munged.log)"
if ! alive /run/slurmctld.pid; then
  say "starting slurmctld"
  /usr/sbin/slurmctld
fi
if ! alive /run/slurmd.pid; then
  say "starting slurmd"
  /usr/sbin/slurmd
fi

# 5. Wait for the node to be idle (ReturnToService=2 brings a restarted node back).
state=""
for _ in $(seq 1 120); do
  state=$(sinfo -h -N -n "$host" -o '%T' 2>/dev/null | head -n 1 || true)
  case "$state" in
    idle|mixed|allocated) break ;;
    drain*|down*) scontrol update NodeName="$host" State=RESUME 2>/dev/null || true ;;
  esac
  sleep 0.5
done
case "$state" in
  idle|mixed|allocated) ;;
  *) die "node $host is '${state:-unknown}' after 60 s (logs: /var/log/slurm/)" ;;
esac
say "ready: node $host is $state"
sinfo
