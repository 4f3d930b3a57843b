#!/usr/bin/env bash
# How long sph render and sph view take next to the run that made the frames (docs/performance.md,
# "Rendering"). Runs each paper scene once, then renders all its frames REPEATS times per
# setting and prints the median seconds and the ratio to the run's own wall time.
# Usage: bash scripts/render_speed.sh [REPEATS] (default 3); run after scripts/build.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
sph=${SPH:-./build/sph}
repeats=${1:-3}
out=out/render_speed
mkdir -p $out

median() { sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}'; }
seconds() { local t0 t1; t0=$(date +%s.%N); "$@" >/dev/null 2>&1; t1=$(date +%s.%N); awk -v a="$t0" -v b="$t1" 'BEGIN {print b - a}'; }

printf "%-14s %-28s %9s %9s\n" scene task seconds "x run"
for scene in dam_break_2d block_3d tank_fill_3d; do
  run_s=$(for i in $(seq "$repeats"); do
    seconds $sph run scenes/paper/$scene.json -o $out/$scene --no-progress; done | median)
  printf "%-14s %-28s %9.2f %9.2f\n" $scene "sph run (101 frames)" "$run_s" 1
  for task in "render --threads 1" "render" "render --mp4" "render --mp4 --no-png" "view"; do
    set -- $task
    cmd=$1; shift
    if [ "$cmd" = view ]; then args=($out/$scene -o $out/$scene.html); else args=($out/$scene -o $out/$scene/render --no-progress "$@"); fi
    s=$(for i in $(seq "$repeats"); do seconds $sph $cmd "${args[@]}"; done | median)
    printf "%-14s %-28s %9.2f %9.2f\n" $scene "sph $task" "$s" "$(awk -v a="$s" -v b="$run_s" 'BEGIN {print a / b}')"
  done
done
