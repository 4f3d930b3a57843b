#!/usr/bin/env bash
# Reproduces the figures of docs/paper-reproduction.md: for each paper scene, one audited
# `sph compare` (accuracy, missed pairs, images; deterministic) and REPEATS timing-only compares
# (no audit) whose median speed ratios are printed as a table. Takes about 15 minutes on 2 cores.
#   bash scripts/paper_reproduction.sh [OUT_DIR] [REPEATS] [THREADS]
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/paper}
repeats=${2:-3}
threads=${3:-2}
[ -x build/sph ] || bash scripts/build.sh
scenes=(tank_fill_3d block_3d dam_break_2d)
for s in "${scenes[@]}"; do
  ./build/sph compare "scenes/paper/$s.json" -o "$out/$s" --threads "$threads" --no-progress
done
for k in $(seq 1 "$repeats"); do
  for s in "${scenes[@]}"; do
    ./build/sph compare "scenes/paper/$s.json" -o "$out/timing/$s-$k" --threads "$threads" --no-audit --frames 1 \
      --no-progress 2>/dev/null
  done
done
python3 - "$out" "$repeats" "${scenes[@]}" <<'PY'
import csv, statistics, sys
out, repeats, scenes = sys.argv[1], int(sys.argv[2]), sys.argv[3:]
print(f"\nMedian over {repeats} runs of the speed ratio to standard (and ms per step):\n")
print("| scene | adaptive | verlet | standard repeat | standard ms/step | adaptive ms/step | verlet ms/step |")
print("| --- | ---: | ---: | ---: | ---: | ---: | ---: |")
for s in scenes:
    ratio, ms = {}, {}
    for k in range(1, repeats + 1):
        for row in csv.DictReader(open(f"{out}/timing/{s}-{k}/phases.csv")):
            ratio.setdefault(row["run"], []).append(float(row["speed_vs_standard"]))
            ms.setdefault(row["run"], []).append(float(row["ms_per_step"]))
    m = lambda d, key: statistics.median(d[key])
    print(f"| {s} | {m(ratio,'adaptive'):.2f}x | {m(ratio,'verlet'):.2f}x | {m(ratio,'standard (perturbed)'):.2f}x "
          f"| {m(ms,'standard'):.3f} | {m(ms,'adaptive'):.3f} | {m(ms,'verlet'):.3f} |")
PY
