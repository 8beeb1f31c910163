#!/usr/bin/env bash
# A one-node Slurm cluster on localhost for the farm test (tests/test_farm_slurm.cpp), entirely
# inside one folder: its own munge key and socket, its own slurm.conf (SLURM_CONF), free ports, state,
# logs and pid files, so it neither needs nor touches /etc/slurm, /run/munge or another cluster
# running beside it (checked on Debian 12, slurm-wlm 22.05; see also /work/shared/notes).
#   slurm_one_node.sh start DIR   start munged, slurmctld and slurmd; return once the node is idle
#   slurm_one_node.sh stop DIR    stop the three daemons started in DIR, by the pids they wrote there
# Needs root (slurmd runs jobs as any user; munged's key must belong to the munge user) and the
# Debian packages slurm-wlm and munge (cmake/packages.txt). Exit 3 when it cannot run at all.
set -euo pipefail
export PATH="$PATH:/usr/sbin:/sbin"

fail() { echo "slurm_one_node: $1" >&2; exit "${2:-1}"; }

cmd="${1:-}" dir="${2:-}"
[[ -n "$dir" && ( "$cmd" == start || "$cmd" == stop ) ]] || fail "usage: $0 start|stop DIR" 3

stop() {
  local pids=()
  for f in slurmd.pid slurmctld.pid munge/munged.pid; do
    [[ -s "$dir/$f" ]] && pids+=("$(cat "$dir/$f")")
  done
  ((${#pids[@]})) || return 0
  kill "${pids[@]}" 2>/dev/null || true
  for _ in $(seq 50); do
    local alive=0
    for p in "${pids[@]}"; do kill -0 "$p" 2>/dev/null && alive=1; done
    ((alive)) || return 0
    sleep 0.1
  done
  kill -9 "${pids[@]}" 2>/dev/null || true
}
if [[ "$cmd" == stop ]]; then stop; exit 0; fi

[[ "$(id -u)" == 0 ]] || fail "must run as root (slurmd and munged need it); the farm test cannot run here" 3
for c in munged munge unmunge slurmctld slurmd sbatch squeue sinfo scontrol scancel python3; do
  command -v "$c" >/dev/null || fail "'$c' not found: install the Debian packages slurm-wlm and munge (cmake/packages.txt)" 3
done
id munge >/dev/null 2>&1 || fail "no 'munge' user: install the Debian package munge" 3

mkdir -p "$dir/state" "$dir/spool" "$dir/munge"
chmod 755 "$dir"  # munged, running as munge, must reach its socket folder
su -s /bin/sh munge -c "test -x '$dir'" ||
  fail "the munge user cannot reach $dir (a folder above it is not searchable by others)" 3
host="$(hostname -s)"
cpus="$(nproc)"
mem_mb=$(($(awk '/MemAvailable/ {print $2}' /proc/meminfo) / 1024 / 2))
read -r ctld_port d_port < <(python3 -c '
import socket
socks = [socket.socket() for _ in range(2)]
for s in socks: s.bind(("", 0))
print(*[s.getsockname()[1] for s in socks])')

# munge: a key of our own, readable only by the munge user, and a socket in our folder.
dd if=/dev/urandom of="$dir/munge/munge.key" bs=128 count=1 status=none
chmod 400 "$dir/munge/munge.key"
chown -R munge:munge "$dir/munge"
chmod 755 "$dir/munge"
sock="$dir/munge/munge.sock"
su -s /bin/sh munge -c "munged --socket='$sock' --key-file='$dir/munge/munge.key' --pid-file='$dir/munge/munged.pid' \
  --log-file='$dir/munge/munged.log' --seed-file='$dir/munge/munged.seed'" ||
  fail "munged did not start: $(tail -n 3 "$dir/munge/munged.log" 2>/dev/null | tr '\n' ' ')"
for _ in $(seq 100); do
  munge -S "$sock" -n 2>/dev/null | unmunge -S "$sock" >/dev/null 2>&1 && break
  sleep 0.1
done
munge -S "$sock" -n | unmunge -S "$sock" >/dev/null 2>&1 || fail "munged does not answer on $sock"

cat >"$dir/slurm.conf" <<EOF
ClusterName=ptfarm
SlurmctldHost=$host
SlurmctldPort=$ctld_port
SlurmdPort=$d_port
AuthType=auth/munge
AuthInfo=socket=$sock
CredType=cred/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SlurmUser=root
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
ReturnToService=2
MpiDefault=none
JobCompType=jobcomp/none
MinJobAge=600
NodeName=$host CPUs=$cpus RealMemory=$mem_mb State=UNKNOWN
PartitionName=main Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF="$dir/slurm.conf"
slurmctld || fail "slurmctld did not start: $(tail -n 3 "$dir/slurmctld.log" 2>/dev/null | tr '\n' ' ')"
slurmd || fail "slurmd did not start: $(tail -n 3 "$dir/slurmd.log" 2>/dev/null | tr '\n' ' ')"
for _ in $(seq 300); do
  [[ "$(sinfo -h -o %T 2>/dev/null)" == idle ]] && exit 0
  sleep 0.1
done
fail "the node did not become idle in 30 s (sinfo: $(sinfo -h 2>&1 | tr '\n' ' '); slurmd.log: $(tail -n 3 "$dir/slurmd.log" 2>/dev/null | tr '\n' ' '))"
