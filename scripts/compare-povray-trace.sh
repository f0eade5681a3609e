#!/bin/bash
# Render time of whitted against POV-Ray 3.7's own "Trace Time" on the SPD
# scenes at 1024x1024, two threads, one sample (the speed issue's bar 1):
#   whitted render X.nff --width 1024 --height 1024 --threads 2
#     (the time on its summary line: build + trace, not reading or writing)
#   povray +IX.pov +W1024 +H1024 -A +WT2 -D   (its "Trace Time" line)
# POV-Ray by default stops rays whose weight on the pixel falls below 1/255
# (adc_bailout); whitted's NFF reader follows the SPD rules and traces the
# whole tree to depth 5. With STRICT=1, POV-Ray reads each scene through a
# wrapper that sets `global_settings { adc_bailout 0 }` (the strict
# comparison ../shared/scenes/spd/README.md describes), so both trace the
# same ray tree; only mount and rings differ much (POV-Ray's "Saved" rays).
# Best of N runs each, interleaved, printed as a Markdown table. With BEFORE
# set to a second whitted binary, it is run in the same loop and gets a
# column of its own (before/after figures measured side by side).
# Run from the repository root after `cargo build --release`:
#   N=3 scripts/compare-povray-trace.sh            (all 14 scenes)
#   N=3 scripts/compare-povray-trace.sh balls mount
# Environment: SHARED (default ../shared), WHITTED (default
# target/release/whitted), BEFORE (unset), SIZE (default 1024), OUT
# (default /tmp/pov_trace), STRICT (1 for adc_bailout 0; default 0).
set -euo pipefail
N=${N:-3}
SIZE=${SIZE:-1024}
SHARED=$(cd "${SHARED:-../shared}" && pwd)
WHITTED=$(realpath "${WHITTED:-target/release/whitted}")
BEFORE=${BEFORE:+$(realpath "$BEFORE")}
# Absolute: POV-Ray runs from the scenes' folder. Debian's POV-Ray reads
# and writes only under /tmp, $HOME and its working folder
# (/etc/povray/3.7/povray.conf), so OUT must lie there.
OUT=$(mkdir -p "${OUT:-/tmp/pov_trace}" && cd "${OUT:-/tmp/pov_trace}" && pwd)
scenes=("$@")
if [ ${#scenes[@]} -eq 0 ]; then
  scenes=(balls gears mount rings teapot tetra tree jacks lattice nurbtst sample shells sombrero teapot_sf6)
fi
# The seconds on whitted's summary line ("... 1 spp in 0.590 s (world ...").
whitted_time() {
  "$1" render "$SHARED/scenes/spd/$2.nff" -o "$OUT/$2.whitted.png" \
    --width "$SIZE" --height "$SIZE" --threads 2 2>&1 |
    sed -n 's/.* spp in \([0-9.]*\) s.*/\1/p'
}
# The seconds in POV-Ray's "Trace Time: ... (1.769 seconds)" line.
povray_time() {
  local input="$1.pov"
  if [ "${STRICT:-0}" = 1 ]; then
    input="$OUT/$1.strict.pov"
    printf 'global_settings { adc_bailout 0 }\n#include "%s.pov"\n' "$1" >"$input"
  fi
  (cd "$SHARED/scenes/spd/pov" &&
    povray "+I$input" "+O$OUT/$1.pov.png" "+W$SIZE" "+H$SIZE" -A +WT2 -D +L. 2>&1) |
    sed -n 's/.*Trace Time:.*(\([0-9.]*\) seconds).*/\1/p'
}
min() { echo "if ($1 < $2) $1 else $2" | bc; }
if [ "${STRICT:-0}" = 1 ]; then
  echo "POV-Ray with adc_bailout 0 (STRICT=1): both trace the whole ray tree."
else
  echo "POV-Ray with its default adc_bailout (1/255); STRICT=1 sets it to 0."
fi
echo
if [ -n "$BEFORE" ]; then
  echo "| scene | POV-Ray trace | whitted before | whitted | ratio before | ratio |"
  echo "|---|---|---|---|---|---|"
else
  echo "| scene | POV-Ray trace | whitted render | ratio |"
  echo "|---|---|---|---|"
fi
for f in "${scenes[@]}"; do
  bw=999; bp=999; bb=999
  for i in $(seq "$N"); do
    # The binary run right after POV-Ray starts on memory POV-Ray left
    # (a few ms slower on the small scenes): the two take turns.
    if [ -n "$BEFORE" ] && [ $((i % 2)) -eq 0 ]; then
      bb=$(min "$(whitted_time "$BEFORE" "$f")" "$bb")
      bw=$(min "$(whitted_time "$WHITTED" "$f")" "$bw")
    else
      bw=$(min "$(whitted_time "$WHITTED" "$f")" "$bw")
      if [ -n "$BEFORE" ]; then
        bb=$(min "$(whitted_time "$BEFORE" "$f")" "$bb")
      fi
    fi
    bp=$(min "$(povray_time "$f")" "$bp")
  done
  ratio=$(echo "scale=4; $bp / $bw" | bc)
  if [ -n "$BEFORE" ]; then
    printf "| %s | %.3f s | %.3f s | %.3f s | %.2fx | %.2fx |\n" "$f" "$bp" "$bb" "$bw" \
      "$(echo "scale=4; $bp / $bb" | bc)" "$ratio"
  else
    printf "| %s | %.3f s | %.3f s | %.2fx |\n" "$f" "$bp" "$bw" "$ratio"
  fi
done
