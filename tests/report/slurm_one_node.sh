#!/usr/bin/env bash
# A Slurm cluster of one node on this machine, for tests: munged, slurmctld and slurmd on loopback, each started
# here with a key, a config and state written into DIR (nothing outside DIR is touched, no system service is used).
#   slurm_one_node.sh start DIR   exit 0: up and idle; use SLURM_CONF=DIR/slurm.conf. Exit 77: cannot be had here
#                                 (not installed, not root, or a daemon refused to start); the reason is on stderr.
#   slurm_one_node.sh stop DIR    stops the daemons `start` started (by the pids it recorded), waits for them.
set -uo pipefail
action=${1:-}
dir=${2:-}
[[ ( $action == start || $action == stop ) && -n $dir ]] || { echo "usage: $0 start|stop DIR" >&2; exit 2; }
mkdir -p "$dir"
dir=$(cd "$dir" && pwd)

stop() {
  local pids=()
  for f in slurmd.bgpid slurmctld.bgpid munged.bgpid; do
    [[ -f $dir/$f ]] && pids+=("$(cat "$dir/$f")") && rm -f "$dir/$f"
  done
  ((${#pids[@]})) || return 0
  kill -TERM "${pids[@]}" 2>/dev/null
  for _ in $(seq 50); do
    kill -0 "${pids[@]}" 2>/dev/null || return 0
    sleep 0.1
  done
  kill -KILL "${pids[@]}" 2>/dev/null
  return 0
}

# Says what refused, with the end of its log, stops what was started, and exits 77 (the test skips).
refuse() {
  echo "slurm_one_node: $1" >&2
  for log in "${@:2}"; do [[ -f $log ]] && { echo "--- $log" >&2; tail -n 15 "$log" >&2; }; done
  stop
  exit 77
}

if [[ $action == stop ]]; then stop; exit 0; fi

for tool in munged slurmctld slurmd sbatch sinfo; do
  command -v "$tool" >/dev/null || refuse "$tool is not installed (Debian packages munge and slurm-wlm; scripts/setup.sh)"
done
# slurmd starts each job as its submitter, which needs root.
[[ $(id -u) == 0 ]] || refuse "slurmd needs root here (it starts jobs as their users); running as $(id -un)"

mkdir -p "$dir/munge" "$dir/state" "$dir/spool" "$dir/log"
chmod 700 "$dir/munge"
head -c 1024 /dev/urandom > "$dir/munge/munge.key"
chmod 400 "$dir/munge/munge.key"
munged -F --force --socket="$dir/munge/munge.sock" --key-file="$dir/munge/munge.key" \
  --pid-file="$dir/munge/munged.pid" --seed-file="$dir/munge/munged.seed" --log-file="$dir/log/munged.log" \
  > "$dir/log/munged.out" 2>&1 &
echo $! > "$dir/munged.bgpid"
for _ in $(seq 50); do [[ -S $dir/munge/munge.sock ]] && break; sleep 0.1; done
[[ -S $dir/munge/munge.sock ]] || refuse "munged did not start" "$dir/log/munged.out" "$dir/log/munged.log"

# Two ports of their own, so a system Slurm (or another test's) is not disturbed.
base=$((20000 + ($$ % 20000) * 2))
cat > "$dir/slurm.conf" <<EOF
ClusterName=varslamtest
SlurmctldHost=localhost(127.0.0.1)
SlurmctldPort=$base
SlurmdPort=$((base + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/munge/munge.sock
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
SchedulerType=sched/backfill
MpiDefault=none
ReturnToService=2
MailProg=/bin/true
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
NodeName=varslamnode NodeHostname=$(hostname) NodeAddr=127.0.0.1 CPUs=$(nproc) RealMemory=4096 State=UNKNOWN
PartitionName=bench Nodes=varslamnode Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF=$dir/slurm.conf
slurmctld -D -i > "$dir/log/slurmctld.out" 2>&1 &
echo $! > "$dir/slurmctld.bgpid"
slurmd -D -N varslamnode > "$dir/log/slurmd.out" 2>&1 &
echo $! > "$dir/slurmd.bgpid"
for _ in $(seq 100); do
  kill -0 "$(cat "$dir/slurmctld.bgpid")" 2>/dev/null ||
    refuse "slurmctld exited" "$dir/log/slurmctld.out" "$dir/log/slurmctld.log"
  kill -0 "$(cat "$dir/slurmd.bgpid")" 2>/dev/null || refuse "slurmd exited" "$dir/log/slurmd.out" "$dir/log/slurmd.log"
  [[ $(sinfo -h -o %T 2>/dev/null) == idle ]] && { echo "slurm_one_node: up (SLURM_CONF=$dir/slurm.conf)"; exit 0; }
  sleep 0.2
done
refuse "the node did not become idle within 20 s ($(sinfo -h -o %T 2>&1))" "$dir/log/slurmctld.log" \
  "$dir/log/slurmd.log"
