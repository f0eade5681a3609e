#!/usr/bin/env bash
# Renders the pictures of docs/shapes.md into docs/images/: each new shape's
# example scene, the CSG scene csg.toml and the mixed scene
# classic-shapes.toml (and the caustic of docs/scene-format.md,
# scenes/caustics.toml), at the scene's own aspect ratio, 480 pixels wide,
# 4 samples per pixel.
#
#   scripts/render-gallery.sh [WHITTED]
#
# WHITTED is the binary (default target/release/whitted; build it with
# `cargo build --release`, or pass $CARGO_TARGET_DIR/release/whitted).
set -euo pipefail
cd "$(dirname "$0")/.."
whitted=${1:-target/release/whitted}
out=docs/images
mkdir -p "$out"
render() {
  local name=$1 height=$2
  "$whitted" render "scenes/$name.toml" --quiet -o "$out/$name.png" \
    --width 480 --height "$height" --spp 4
}
render classic-shapes 300
render quadrics 300
render tori 360
render superellipsoids 300
render implicit 360
render patches 360
render csg 360
render caustics 300
