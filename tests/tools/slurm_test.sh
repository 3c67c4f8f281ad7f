#!/usr/bin/env bash
# The Slurm path end to end on a real single-node Slurm: munge key, a minimal slurm.conf with one
# node of nproc CPUs, munged, slurmctld and slurmd started here (as root, on private ports and
# sockets, in a temporary folder), then `weft slurm --shards 4` for a fiber bake, a sweep and a
# draft verify (sbatch --array and a dependent merge job), each merged output compared byte for
# byte with the one-process run (verify's metrics.json but for its timings); the daemons are
# stopped at the end. Installs nothing (scripts/install-deps.sh --tests, which scripts/test.sh
# runs, installs slurm-wlm and munge);
# exits 77 (skipped, with the reason) only where the scheduler
# cannot start: not root, no slurm-wlm or munge, or the daemons do not come up.
# Usage: slurm_test.sh WEFT_EXE SOURCE_DIR
set -uo pipefail
weft=$(readlink -f "$1")
src=$(readlink -f "$2")
skip() { echo "slurm_test: SKIPPED: $*"; exit 77; }
[ "$(id -u)" -eq 0 ] || skip "needs root to start munged, slurmctld and slurmd"
for b in munged slurmctld slurmd sbatch squeue sinfo; do
  command -v "$b" >/dev/null || skip "$b not found (scripts/install-deps.sh --tests installs slurm-wlm and munge)"
done

T=$(mktemp -d /tmp/weft-slurm.XXXXXX)
chmod 755 "$T"
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null; done
  for p in "${pids[@]}"; do wait "$p" 2>/dev/null; done
  [ "${KEEP:-0}" = 1 ] || rm -rf "$T"
}
trap cleanup EXIT

# munge: its own key, socket and folders.
mkdir -p "$T/munge" "$T/state" "$T/spool" "$T/out"
chmod 700 "$T/munge"
dd if=/dev/urandom of="$T/munge/munge.key" bs=1024 count=1 status=none
chmod 400 "$T/munge/munge.key"
munged --foreground --force --key-file="$T/munge/munge.key" --socket="$T/munge/socket" \
  --pid-file="$T/munge/pid" --log-file="$T/munge/log" --seed-file="$T/munge/seed" \
  >"$T/munged.out" 2>&1 &
pids+=($!)

host=$(hostname -s)
cpus=$(nproc)
port=$((20000 + RANDOM % 20000))
cat > "$T/slurm.conf" <<CONF
ClusterName=weft-test
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$T/munge/socket
StateSaveLocation=$T/state
SlurmdSpoolDir=$T/spool
SlurmctldPidFile=$T/slurmctld.pid
SlurmdPidFile=$T/slurmd.pid
SlurmctldLogFile=$T/slurmctld.log
SlurmdLogFile=$T/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SwitchType=switch/none
MpiDefault=none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/builtin
ReturnToService=2
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
SlurmctldTimeout=10
SlurmdTimeout=10
MinJobAge=30
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=weft Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$T/slurm.conf
for i in $(seq 50); do [ -S "$T/munge/socket" ] && break; sleep 0.1; done
[ -S "$T/munge/socket" ] || skip "munged did not start: $(cat "$T/munge/log" 2>/dev/null)"
slurmctld -D -i -f "$SLURM_CONF" >"$T/slurmctld.out" 2>&1 &
pids+=($!)
slurmd -D -f "$SLURM_CONF" -N "$host" >"$T/slurmd.out" 2>&1 &
pids+=($!)
up=0
for i in $(seq 100); do
  state=$(sinfo -h -o %t 2>/dev/null | head -1)
  [ "$state" = idle ] && up=1 && break
  sleep 0.2
done
[ $up = 1 ] || skip "slurmctld/slurmd did not come up (state '$state'): $(tail -3 "$T/slurmctld.log" "$T/slurmd.log" 2>/dev/null)"
echo "slurm_test: single-node Slurm up ($cpus CPUs) after $i polls"

fail=0
# Submits through weft slurm, waits for the merge job, compares with the one-process run.
check() {
  local name=$1 out=$2
  shift 2
  "$weft" slurm --shards 4 "$@" -o "$T/out/$out" || { echo "FAIL $name: weft slurm"; fail=1; return; }
  for i in $(seq 600); do
    [ -z "$(squeue -h 2>/dev/null)" ] && break
    sleep 0.1
  done
  "$weft" "$@" -o "$T/out/one-$out" >/dev/null || { echo "FAIL $name: one-process run"; fail=1; return; }
  if [ -f "$T/out/$out" ] && cmp -s "$T/out/$out" "$T/out/one-$out"; then
    echo "slurm_test: $name: 4 shards through sbatch --array + merge == one process (bytes)"
  else
    echo "FAIL $name: merged output missing or different"
    tail -5 "$T/out/$out.slurm/"*.log 2>/dev/null
    fail=1
  fi
}
cd "$T"
check "bake fiber" fiber.exr bake fiber red-cotton --photons 400 --resolution 2 --passes 2 --quiet
check "sweep" sweep.csv sweep "$src/scenes/examples/woven-patch.json" --spp 1 --resolution 8 --quiet

# verify: its report folder; inplane.csv byte for byte, metrics.json but for its timings
# ("seconds"). The shards share one fiber bake through the bake cache.
t0=$(date +%s.%N)
"$weft" slurm --shards 4 verify --quality draft --quiet -o "$T/out/report" ||
  { echo "FAIL verify: weft slurm"; fail=1; }
for i in $(seq 1200); do
  [ -z "$(squeue -h 2>/dev/null)" ] && break
  sleep 0.1
done
t1=$(date +%s.%N)
"$weft" verify --quality draft --quiet -o "$T/out/one-report" >/dev/null ||
  { echo "FAIL verify: one-process run"; fail=1; }
t2=$(date +%s.%N)
awk -v a="$t0" -v b="$t1" -v c="$t2" 'BEGIN { printf "slurm_test: verify draft wall time: " \
  "4 shards + merge through Slurm %.1f s, one process %.1f s\n", b - a, c - b }'
same_metrics() {
  python3 -c 'import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:])
for j in (a, b): j.pop("seconds", None)
sys.exit(a != b)' "$1/metrics.json" "$2/metrics.json"
}
if [ -f "$T/out/report/inplane.csv" ] &&
  cmp -s "$T/out/report/inplane.csv" "$T/out/one-report/inplane.csv" &&
  same_metrics "$T/out/report" "$T/out/one-report"; then
  echo "slurm_test: verify: 4 shards through sbatch --array + merge == one process (inplane.csv bytes, metrics)"
else
  echo "FAIL verify: merged report missing or different"
  tail -5 "$T/out/report.slurm/"*.log 2>/dev/null
  fail=1
fi
exit $fail
