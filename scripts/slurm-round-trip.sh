#!/usr/bin/env bash
# Times the Slurm recipe of docs/cluster.md against a direct render of the
# same image: submit.sh with N tiles (default 4) up to the merged file,
# then `whitted render` on all cores; checks that both files are the same.
# Needs a running cluster (scripts/slurm-single-node.sh).
#
#   scripts/slurm-round-trip.sh BINARY [N] [SCENE] [RENDER OPTIONS...]
set -euo pipefail
binary=$(realpath "${1:?usage: slurm-round-trip.sh BINARY [N] [SCENE] [RENDER OPTIONS...]}")
count=${2:-4}
shift $(( $# >= 2 ? 2 : 1 ))
here=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
start=$(date +%s.%N)
job=$(WHITTED=$binary "$here/deploy/slurm/submit.sh" "$count" parts slurm.png "$@")
while squeue -h -j "$job" 2>/dev/null | grep -q .; do sleep 0.05; done
state=$(scontrol show job -o "$job" | grep -o 'JobState=[A-Z]*')
end=$(date +%s.%N)
[ "$state" = JobState=COMPLETED ] || { cat ./*.log; exit 1; }
"$binary" render "$@" -o direct.png --quiet
direct_end=$(date +%s.%N)
cmp slurm.png direct.png
echo "slurm $count tiles: $(awk "BEGIN { printf \"%.2f\", $end - $start }") s; direct: $(awk "BEGIN { printf \"%.2f\", $direct_end - $end }") s; same file"
