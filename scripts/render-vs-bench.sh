#!/bin/bash
# Does the render path keep up with the traversal kernel? (the speed issue's
# bar 2). For each model (an .obj: the renderer lights it with one point
# light, no mirrors, so it traces primary and shadow rays only), on THREADS
# threads (default 1), best of N interleaved runs each:
#   whitted render MODEL --width 1024 --height 1024 --stats
#     its rays per second of trace time (all kinds);
#   whitted bench MODEL --accel bvh --json
#     its single-ray rates for primary and shadow rays, combined for the
#     render's own counts of each kind: count_p + count_s over
#     count_p / rate_p + count_s / rate_s.
# and the ratio render / bench (1.0 = the render path costs nothing over
# the traversal). Run from the repository root after `cargo build --release`:
#   N=3 scripts/render-vs-bench.sh ../shared/scenes/models/bunny/bunny.obj
# Environment: WHITTED (default target/release/whitted), THREADS (default 1;
# otherwise the bench side is its all-cores rate).
set -euo pipefail
N=${N:-3}
THREADS=${THREADS:-1}
WHITTED=$(realpath "${WHITTED:-target/release/whitted}")
echo "| model | render Mrays/s | bench Mrays/s (same mix) | render / bench |"
echo "|---|---|---|---|"
for model in "$@"; do
  best_render=0; best_bench=0
  for _ in $(seq "$N"); do
    stats=$("$WHITTED" render "$model" --width 1024 --height 1024 --threads "$THREADS" \
      --stats --quiet -o /tmp/render-vs-bench.png 2>&1)
    render=$(echo "$stats" | awk '$1 == "all" { print $5 }')
    primary=$(echo "$stats" | awk '$1 == "primary" { print $2 }')
    shadow=$(echo "$stats" | awk '$1 == "shadow" { print $2 }')
    bench=$("$WHITTED" bench "$model" --accel bvh --runs 1 --json |
      python3 -c '
import json, sys
primary, shadow = int(sys.argv[1]), int(sys.argv[2])
key = "mrays_per_s_1_thread" if sys.argv[3] == "1" else "mrays_per_s_all_threads"
rate = {k["rays"]: k[key] for k in json.load(sys.stdin)["structures"][0]["kinds"]}
print((primary + shadow) / (primary / rate["primary"] + shadow / rate["shadow"]))
' "$primary" "$shadow" "$THREADS")
    best_render=$(echo "if ($render > $best_render) $render else $best_render" | bc)
    best_bench=$(echo "if ($bench > $best_bench) $bench else $best_bench" | bc)
  done
  printf "| %s | %.2f | %.2f | %.2fx |\n" "$(basename "$model" .obj)" "$best_render" "$best_bench" \
    "$(echo "scale=3; $best_render / $best_bench" | bc)"
done
