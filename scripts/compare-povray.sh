#!/bin/bash
# Whole-process wall time of whitted and POV-Ray 3.7 (apt-get install povray)
# on the SPD scenes at 512x512, one sample, both cores: best of N runs each,
# interleaved. Run from the repository root after `cargo build --release`:
#   N=3 scripts/compare-povray.sh balls gears mount ...
# Environment: SHARED (default ../shared), WHITTED (default
# target/release/whitted), OUT (default /tmp/pov_out).
set -euo pipefail
N=${N:-3}
SHARED=$(cd "${SHARED:-../shared}" && pwd)
WHITTED=$(realpath "${WHITTED:-target/release/whitted}")
OUT=${OUT:-/tmp/pov_out}
mkdir -p "$OUT"
now() { date +%s.%N; }
for f in "$@"; do
  bw=999; bp=999
  for _ in $(seq "$N"); do
    t0=$(now)
    "$WHITTED" render "$SHARED/scenes/spd/$f.nff" -o "$OUT/$f.whitted.png" --width 512 --height 512 --quiet
    t1=$(now)
    (cd "$SHARED/scenes/spd/pov" && povray "+I$f.pov" "+O$OUT/$f.pov.png" +W512 +H512 -D -V +WT2 -A -GA >/dev/null 2>&1)
    t2=$(now)
    bw=$(echo "if ($t1 - $t0 < $bw) $t1 - $t0 else $bw" | bc)
    bp=$(echo "if ($t2 - $t1 < $bp) $t2 - $t1 else $bp" | bc)
  done
  printf "%-11s whitted %6.3f s  povray %6.3f s  ratio %5.1f\n" "$f" "$bw" "$bp" "$(echo "scale=3; $bp / $bw" | bc)"
done
