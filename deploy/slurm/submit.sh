#!/bin/bash
# Renders a frame on a Slurm cluster in N tiles and merges it
# (docs/cluster.md): a job array of N tasks, then a merge job that waits
# for all of them (--dependency=afterok). Prints the merge job's id.
#
#   submit.sh N PARTS OUT [SCENE] [RENDER OPTIONS...] [-- MERGE OPTIONS...]
#
# PARTS (created if missing) and OUT must be on storage every node sees.
# Example:
#   WHITTED=$HOME/bin/whitted deploy/slurm/submit.sh 16 /shared/parts /shared/frame.exr \
#       scenes/whitted.toml --width 3840 --height 2160 --spp 16 --aov depth -- --aov depth=/shared/depth.exr
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
usage="usage: submit.sh N PARTS OUT [SCENE] [RENDER OPTIONS...] [-- MERGE OPTIONS...]"
count=${1:?$usage}
parts=${2:?$usage}
out=${3:?$usage}
shift 3
render=()
while [ $# -gt 0 ] && [ "$1" != -- ]; do
  render+=("$1")
  shift
done
[ $# -gt 0 ] && shift
mkdir -p "$parts"
tiles=$(sbatch --parsable --array="0-$((count - 1))" "$here/render-tiles.sbatch" "$parts" "${render[@]}")
tiles=${tiles%%;*}
merge=$(sbatch --parsable --dependency="afterok:$tiles" --kill-on-invalid-dep=yes \
  "$here/merge.sbatch" "$count" "$parts" "$out" "$@")
echo "${merge%%;*}"
