#!/usr/bin/env bash
# The farm on a real Slurm: starts a single-node Slurm on this machine (Debian's slurm-wlm:
# munged, slurmctld and slurmd on localhost, in a private folder), bakes bevy's Cornell box
# through the script `lmbake farm slurm` writes, and checks that the output equals
# `lmbake bake` byte for byte. Then stops the daemons. Not part of .ci/run (it starts system
# daemons and takes a few minutes); run it as root on a machine without a Slurm of its own.
# The bake runs as one Slurm job of WORKERS tasks (srun starts them together; default: the
# machine's cores), after a plan job; its wall time is printed against `lmbake bake`'s.
#   usage: tools/slurm-test.sh [SHARDS] [SCENE] [CONFIG] [WORKERS]  (default: 4, bevy's Cornell box, a small config)
# docs/farm.md says how to start such a Slurm by hand.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
shards=${1:-4}
scene=$(realpath "${2:-assets/scenes/cornell-box-bevy/CornellBox.glb}")

LMB_SETUP_PACKAGES="slurm-wlm munge" bash tools/setup.sh build >/dev/null
lmbake=$root/build/lmbake

work=$(mktemp -d /tmp/lmbake-slurm.XXXXXX)
if [ -n "${3:-}" ]; then
  config=$(realpath "$3")
else
  config=$work/bake.yaml
  printf 'atlas: {texels: 40000}\nbounces: 2\nsamples: {gather: 64, bounce: 16}\noutput: {directional: true}\nfarm: {min_step_rays: 0}\n' >"$config"
fi

# --- a single-node Slurm in $work/slurm -----------------------------------------------------
sl=$work/slurm
mkdir -p "$sl/state" "$sl/spool" "$sl/log" "$sl/munge"
chmod 700 "$sl/munge"
dd if=/dev/urandom of="$sl/munge/munge.key" bs=1024 count=1 status=none
chmod 400 "$sl/munge/munge.key"
munge_socket=$sl/munge/munge.socket
cpus=$(nproc)
mem=$(awk '/MemTotal/ {print int($2 / 1024 * 0.8)}' /proc/meminfo)
cat >"$sl/slurm.conf" <<EOF
ClusterName=lmbake-test
SlurmctldHost=localhost
SlurmUser=root
AuthType=auth/munge
AuthInfo=socket=$munge_socket
StateSaveLocation=$sl/state
SlurmdSpoolDir=$sl/spool
SlurmctldPidFile=$sl/slurmctld.pid
SlurmdPidFile=$sl/slurmd.pid
SlurmctldLogFile=$sl/log/slurmctld.log
SlurmdLogFile=$sl/log/slurmd.log
SlurmctldPort=16817
SlurmdPort=16818
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
ReturnToService=2
SchedulerType=sched/backfill
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
MaxArraySize=100001
NodeName=localhost CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=bake Nodes=localhost Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF=$sl/slurm.conf

stop() {
  scontrol shutdown >/dev/null 2>&1 || true
  sleep 1
  for f in slurmctld.pid slurmd.pid munged.pid; do
    [ -f "$sl/$f" ] && kill "$(cat "$sl/$f")" 2>/dev/null || true
  done
}
trap stop EXIT

munged --force --socket="$munge_socket" --key-file="$sl/munge/munge.key" --pid-file="$sl/munged.pid" \
  --log-file="$sl/log/munged.log" --seed-file="$sl/munge/seed"
slurmctld -f "$sl/slurm.conf"
slurmd -f "$sl/slurm.conf"
for _ in $(seq 1 30); do
  sinfo -h -o '%T' 2>/dev/null | grep -q idle && break
  sleep 1
done
echo "slurm: $(sinfo -h -o '%P %D node(s) %c cpus %T' | head -1) (slurm-wlm $(slurmctld -V | awk '{print $2}'))"

# --- the bake, on one machine and through Slurm ----------------------------------------------
workers=${4:-$cpus}
tb=$(date +%s.%N)
"$lmbake" bake "$scene" -c "$config" -o "$work/bake" -q --threads "$workers"
bake_s=$(echo "$(date +%s.%N) - $tb" | bc)
farm=$work/farm
t0=$(date +%s.%N)
"$lmbake" farm slurm "$scene" -c "$config" --farm "$farm" -o "$work/out" --shards "$shards" --workers "$workers" --threads 1
for _ in $(seq 1 1800); do
  [ -f "$farm/finished" ] || [ -f "$farm/failed" ] && break
  sleep 1
done
t1=$(date +%s.%N)
if [ ! -f "$farm/finished" ]; then
  echo "FAIL: the Slurm bake did not finish (logs: $farm/logs, $sl/log)" >&2
  tail -5 "$farm"/logs/*.out >&2 || true
  exit 1
fi
steps=$(cat "$farm/end")
slurm_s=$(echo "$t1 - $t0" | bc)
echo "slurm bake: $steps steps in $shards shards, a plan job and a job of $workers worker tasks x 1 thread:" \
  "$(printf '%.1f' "$slurm_s") s (submission to DIR/finished); lmbake bake --threads $workers: $(printf '%.1f' "$bake_s") s;" \
  "ratio $(printf '%.2f' "$(echo "$slurm_s / $bake_s" | bc -l)")"
differ=0
n=0
for f in "$work/bake"/*; do
  n=$((n + 1))
  if cmp -s "$f" "$work/out/$(basename "$f")"; then
    echo "  same: $(basename "$f") $(sha256sum <"$f" | cut -c1-16)"
  else
    echo "  DIFFERS: $(basename "$f")"
    differ=1
  fi
done
[ "$(ls "$work/bake" | wc -l)" = "$(ls "$work/out" | wc -l)" ] || { echo "FAIL: file lists differ" >&2; exit 1; }
if [ $differ = 0 ]; then
  echo "ok: the Slurm bake in $shards shards equals lmbake bake in all $n files, byte for byte ($work)"
else
  echo "FAIL: the Slurm bake differs from lmbake bake" >&2
  exit 1
fi
