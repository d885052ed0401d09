#!/usr/bin/env bash
# Submits a sharded shadowbake bake to Slurm: a job array of N shard tasks and a merge job that
# depends on all of them (afterok). Prints the two job ids. The shards go to OUT.shards/, the
# merged bake to OUT/.
#
#   deploy/slurm/submit.sh SCENE OUT N [BAKE OPTIONS...]
#
# SHADOWBAKE names the binary (default: shadowbake on the PATH); the scene, OUT and the binary
# must be on a file system every node sees. Extra sbatch options go in SBATCH_OPTIONS (e.g.
# "--partition=bake --time=02:00:00").
set -euo pipefail
if [ $# -lt 3 ]; then
  echo "usage: $0 SCENE OUT N [BAKE OPTIONS...]" >&2
  exit 2
fi
scene=$(realpath "$1") out=$(realpath -m "$2") shards=$3
shift 3
here=$(cd "$(dirname "$0")" && pwd)
work="$out.shards"
mkdir -p "$work" "$(dirname "$out")"
read -r -a extra <<<"${SBATCH_OPTIONS:-}"
array=$(sbatch --parsable "${extra[@]}" --array="0-$((shards - 1))" \
  --output="$work/slurm_%A_%a.log" "$here/bake_shards.sbatch" "$scene" "$work" "$shards" "$@")
array=${array%%;*}
merge=$(sbatch --parsable "${extra[@]}" --dependency="afterok:$array" --kill-on-invalid-dep=yes \
  --output="$work/slurm_merge_%j.log" "$here/merge.sbatch" "$work" "$shards" "$out")
merge=${merge%%;*}
echo "$array $merge"
