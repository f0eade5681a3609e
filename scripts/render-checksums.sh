#!/usr/bin/env bash
# Renders every example scene, every SPD database and the kitchen model with
# one `whitted` binary, writing the picture (PNG and PFM) and every AOV, and
# prints one checksum line per file. Two binaries' lists must be identical
# when a change promises the same pictures bit for bit:
#
#   scripts/render-checksums.sh OLD/whitted /tmp/old > old.txt
#   scripts/render-checksums.sh target/release/whitted /tmp/new > new.txt
#   diff old.txt new.txt
#
# Needs ../shared for the SPD scenes and the kitchen (absent ones are listed
# as such, so the two lists still differ if one run had them).
set -euo pipefail
whitted=$(realpath "$1")
out=$2
cd "$(dirname "$0")/.."
shared=../shared/scenes
mkdir -p "$out"
render() {
  local name=$1 scene=$2; shift 2
  "$whitted" render "$scene" --quiet -o "$out/$name.png" "$@"
  "$whitted" render "$scene" --quiet -o "$out/$name.pfm" \
    --aov depth="$out/$name.depth.pfm" --aov normal="$out/$name.normal.pfm" \
    --aov id="$out/$name.id.pfm" --aov cost="$out/$name.cost.pfm" "$@"
}
for scene in scenes/*.toml; do
  name=$(basename "$scene" .toml)
  render "$name" "$scene" --width 160 --height 120
  render "$name.spp4" "$scene" --width 64 --height 48 --spp 4
  for accel in kdtree grid linear; do
    "$whitted" render "$scene" --quiet --width 96 --height 72 --accel $accel \
      -o "$out/$name.$accel.pfm"
  done
done
absent=()
for scene in "$shared"/spd/*.nff; do
  name=$(basename "$scene" .nff)
  if [ -f "$scene" ]; then
    render "spd-$name" "$scene" --width 200 --height 200
  else
    absent+=("$scene")
  fi
done
kitchen=$shared/models/kitchen/kitchen.obj
if [ -f "$kitchen" ]; then
  render kitchen "$kitchen" --width 160 --height 120
else
  absent+=("$kitchen")
fi
cd "$out"
sha256sum -- * | sort -k2
for file in "${absent[@]}"; do echo "absent: $file"; done
