#!/bin/bash
# Trace time of two whitted binaries, side by side, on the same scenes: the
# A/B figure behind a speed change ("old over new"). For each scene, the
# two binaries take turns N times:
#   whitted render SCENE --width SIZE --height SIZE --threads THREADS --stats
# and the best `trace` line of each is kept (the machine is shared and
# noisy: only interleaved best-of runs compare). The pictures of the last
# round are compared byte for byte, so a change that promises the same
# picture is checked on the way. Printed as a Markdown table.
#
# Build both binaries with the same profile: a build with debug info lays
# the code out differently, and that alone moved whitted.toml's trace by 2
# to 7% (docs/performance-log.md, 2026-11-29 afternoon).
#
# Run from the repository root:
#   OLD=/tmp/whitted-old N=9 scripts/compare-trace.sh tree balls
#   OLD=/tmp/whitted-old THREADS=2 scripts/compare-trace.sh scenes/whitted.toml
# A scene is a file, or the name of an SPD database in ../shared/scenes/spd.
# Environment: OLD (required), NEW (default target/release/whitted), N
# (default 7), SIZE (default 1024), THREADS (default 1), SHARED (default
# ../shared), OUT (default /tmp/compare_trace).
set -euo pipefail
if [ -z "${OLD:-}" ] || [ $# -eq 0 ]; then
  sed -n '2,21p' "$0" | sed 's/^# \{0,1\}//'
  exit 2
fi
OLD=$(realpath "$OLD")
NEW=$(realpath "${NEW:-target/release/whitted}")
N=${N:-7}
SIZE=${SIZE:-1024}
THREADS=${THREADS:-1}
SHARED=${SHARED:-../shared}
OUT=${OUT:-/tmp/compare_trace}
mkdir -p "$OUT"
# The seconds on the `trace` line of `--stats`; the script stops when a
# render fails.
trace_time() {
  local seconds
  seconds=$("$1" render "$2" -o "$3" --width "$SIZE" --height "$SIZE" --threads "$THREADS" \
    --stats 2>&1 | awk '$1 == "trace" { print $2 }')
  if [ -z "$seconds" ]; then
    echo "$1 failed on $2" >&2
    exit 1
  fi
  echo "$seconds"
}
min() { echo "if ($1 < $2) $1 else $2" | bc; }
echo "| scene | old trace | new trace | old / new | picture |"
echo "|---|---|---|---|---|"
for scene in "$@"; do
  file=$scene
  [ -f "$file" ] || file="$SHARED/scenes/spd/$scene.nff"
  if [ ! -f "$file" ]; then
    echo "no scene $scene (neither a file nor $file)" >&2
    exit 1
  fi
  rm -f "$OUT/old.png" "$OUT/new.png"
  best_old=999
  best_new=999
  for round in $(seq "$N"); do
    # Each goes first every other round: the first run after a pause
    # starts on a cold cache.
    if [ $((round % 2)) -eq 1 ]; then
      old=$(trace_time "$OLD" "$file" "$OUT/old.png")
      new=$(trace_time "$NEW" "$file" "$OUT/new.png")
    else
      new=$(trace_time "$NEW" "$file" "$OUT/new.png")
      old=$(trace_time "$OLD" "$file" "$OUT/old.png")
    fi
    best_old=$(min "$old" "$best_old")
    best_new=$(min "$new" "$best_new")
  done
  picture=$(cmp -s "$OUT/old.png" "$OUT/new.png" && echo same || echo DIFFERENT)
  printf "| %s | %.3f s | %.3f s | %.3fx | %s |\n" "$(basename "$scene")" "$best_old" \
    "$best_new" "$(echo "scale=4; $best_old / $best_new" | bc)" "$picture"
done
