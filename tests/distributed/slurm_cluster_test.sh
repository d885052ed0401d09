#!/usr/bin/env bash
# Runs deploy/slurm/ for real on a one-node Slurm cluster on localhost: starts munged, slurmctld
# and slurmd (Debian's munge and slurm-wlm) with their state, sockets and logs in a scratch
# folder and their own ports, submits a 4-task job array of shards and the merge with
# deploy/slurm/submit.sh, waits for both, bakes the same scene in one process, and compares the
# two bakes byte for byte (the manifest but for its timings). With TILES, a receiver must have
# been split into that many tiles of rows (pipeline/tiles.h) across the shards. Stops the daemons
# whatever happens. Needs root (slurmd runs jobs as their user) and the packages munge, slurm-wlm
# (.ci/debian-packages). CTest: `ctest -L slurm` (Distributed.SlurmOneNodeCluster: the hall
# level in 4 shards; Distributed.SlurmTiles4096: the courtyard's 4096² ground in 8 tiles).
#
#   tests/distributed/slurm_cluster_test.sh build/shadowbake [SCENE [SHARDS [TILES [OPTIONS...]]]]
set -euo pipefail

fail() {
  echo "slurm_cluster_test: $*" >&2
  exit 1
}
[ $# -ge 1 ] || fail "usage: $0 SHADOWBAKE [SCENE]"
root=$(cd "$(dirname "$0")/../.." && pwd)
shadowbake=$(realpath "$1")
scene=$(realpath "${2:-$root/scenes/hall/scene_level.toml}")
shards=${3:-4}
tiles=${4:-0}
if [ $# -ge 5 ]; then bake_options=("${@:5}"); else bake_options=(--samples 8); fi
[ "$(id -u)" -eq 0 ] || fail "needs root: slurmd starts each job as its user"
for tool in munged slurmctld slurmd sbatch scontrol sinfo; do
  command -v "$tool" >/dev/null || fail "$tool not found (apt-get install munge slurm-wlm)"
done

scratch=$(mktemp -d /tmp/shadowbake-slurm.XXXXXX)
chmod 755 "$scratch"
pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null || true; done
  sleep 0.5
  for pid in "${pids[@]}"; do kill -9 "$pid" 2>/dev/null || true; done
  if [ "${keep:-0}" = 1 ]; then
    echo "slurm_cluster_test: logs kept in $scratch" >&2
  else
    rm -rf "$scratch"
  fi
}
trap cleanup EXIT
keep=1
started=$EPOCHREALTIME
elapsed() { awk "BEGIN { printf \"%.1f s\", $EPOCHREALTIME - $started }"; }

# munge: a fresh key, a private socket.
mkdir -p "$scratch/munge" "$scratch/state" "$scratch/spool" "$scratch/log"
dd if=/dev/urandom of="$scratch/munge/key" bs=1 count=1024 status=none
chmod 400 "$scratch/munge/key"
munged --force --key-file="$scratch/munge/key" --socket="$scratch/munge/socket" \
  --pid-file="$scratch/munge/pid" --log-file="$scratch/munge/log" --seed-file="$scratch/munge/seed"
pids+=("$(cat "$scratch/munge/pid")")

# Ports no other cluster on this machine uses.
port=$((20000 + RANDOM % 20000))
host=$(hostname -s)
cat >"$scratch/slurm.conf" <<CONF
ClusterName=shadowbake-test
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$scratch/munge/socket
CredType=cred/munge
StateSaveLocation=$scratch/state
SlurmdSpoolDir=$scratch/spool
SlurmctldPidFile=$scratch/slurmctld.pid
SlurmdPidFile=$scratch/slurmd.pid
SlurmctldLogFile=$scratch/log/slurmctld.log
SlurmdLogFile=$scratch/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
ReturnToService=2
NodeName=$host NodeAddr=127.0.0.1 CPUs=$(nproc) State=UNKNOWN
PartitionName=bake Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$scratch/slurm.conf"
slurmctld -f "$SLURM_CONF"
for _ in $(seq 50); do [ -s "$scratch/slurmctld.pid" ] && break; sleep 0.1; done
pids+=("$(cat "$scratch/slurmctld.pid")")
slurmd -f "$SLURM_CONF"
for _ in $(seq 50); do [ -s "$scratch/slurmd.pid" ] && break; sleep 0.1; done
pids+=("$(cat "$scratch/slurmd.pid")")
for _ in $(seq 100); do
  state=$(sinfo -h -o %T 2>/dev/null || true)
  [ "$state" = idle ] && break
  sleep 0.2
done
[ "$state" = idle ] || fail "the node did not come up (state '$state'); see $scratch/log"
echo "slurm_cluster_test: one-node cluster '$host' up, $(nproc) CPUs, port $port ($(elapsed))"

# The sharded bake, as a user would submit it.
out="$scratch/out/merged"
export SHADOWBAKE="$shadowbake"
read -r array merge < <("$root/deploy/slurm/submit.sh" "$scene" "$out" "$shards" "${bake_options[@]}")
echo "slurm_cluster_test: submitted array job $array ($shards tasks) and merge job $merge"
job_state() { scontrol show job "$1" 2>/dev/null | grep -o 'JobState=[A-Z_]*' | sort -u | cut -d= -f2 | tr '\n' ' '; }
for _ in $(seq 1800); do
  merge_state=$(job_state "$merge")
  case $merge_state in
    *COMPLETED*) break ;;
    *FAILED* | *CANCELLED* | *TIMEOUT* | *NODE_FAIL* | *OUT_OF_MEMORY*)
      fail "merge job $merge ended $merge_state; array tasks: $(job_state "$array"); logs in $scratch/out/merged.shards" ;;
  esac
  sleep 0.2
done
[[ $merge_state == *COMPLETED* ]] || fail "merge job $merge did not finish in 6 minutes ($merge_state)"
echo "slurm_cluster_test: array and merge completed ($(elapsed))"
ls "$scratch/out/merged.shards" | grep -c '^shard_' | grep -qx "$shards" || fail "not $shards shard folders"
if [ "$tiles" -gt 0 ]; then
  found=$(find "$scratch/out/merged.shards" -name 'receiver_*_rows_*.bin' | wc -l)
  [ "$found" -eq "$tiles" ] || fail "$found tiles in the shards, not $tiles"
  echo "slurm_cluster_test: the shards hold $found tiles of one receiver"
fi

# The same bake in one process (without the incremental cache a merge does not write), and the
# comparison.
"$shadowbake" bake "$scene" -o "$scratch/out/single" -q --no-cache "${bake_options[@]}" 2>/dev/null
/usr/bin/python3 - "$scratch/out/single" "$out" <<'PY'
import json, os, sys
a, b = sys.argv[1], sys.argv[2]
def strip(o):
    if isinstance(o, dict):
        return {k: strip(v) for k, v in o.items() if "seconds" not in k}
    if isinstance(o, list):
        return [strip(v) for v in o]
    return o
files_a, files_b = sorted(os.listdir(a)), sorted(os.listdir(b))
if files_a != files_b:
    sys.exit(f"slurm_cluster_test: the merged bake's files differ: {files_a} vs {files_b}")
for f in files_a:
    x, y = open(os.path.join(a, f), "rb").read(), open(os.path.join(b, f), "rb").read()
    if f == "manifest.json":
        same = strip(json.loads(x)) == strip(json.loads(y))
    else:
        same = x == y
    if not same:
        sys.exit(f"slurm_cluster_test: {f} differs between the single bake and the merged shards")
print(f"slurm_cluster_test: merged shards equal the single bake, {len(files_a)} files byte for byte"
      " (manifest: but for timings)")
PY
keep=0
echo "slurm_cluster_test: ok ($(elapsed) in all)"
