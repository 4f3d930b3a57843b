#!/usr/bin/env bash
# Times every compared neighbor mode on the paper's three scenes, side by side: the modes run
# interleaved (standard, adaptive, ..., standard, ...) RUNS times each, and the table gives the
# median wall time per step, its ratio to standard's, the list entries (re)written per step and,
# from one audited run per mode, the pairs within h the lists missed.
#   bash scripts/neighbor_modes.sh [SPH] [RUNS] [OUT_DIR]     (defaults: ./build/sph 3 out/neighbor_modes)
set -euo pipefail
sph=${1:-./build/sph} runs=${2:-3} out=${3:-out/neighbor_modes}
modes=$("$sph" bench --help | sed -n 's/.*--modes TEXT=\([a-z_,]*\).*/\1/p')
mkdir -p "$out"
for scene in dam_break_2d block_3d tank_fill_3d; do
  for r in $(seq "$runs"); do
    for m in ${modes//,/ }; do
      "$sph" run "scenes/paper/$scene.json" --neighbors "$m" -o "$out/$scene.$m.$r" --every 0 --no-progress >/dev/null 2>&1
    done
  done
  for m in ${modes//,/ }; do
    "$sph" run "scenes/paper/$scene.json" --neighbors "$m" --audit -o "$out/$scene.$m.audit" --every 0 --no-progress >/dev/null 2>&1
  done
done
python3 - "$out" "$runs" "$modes" <<'PY'
import csv, json, statistics, sys
out, runs, modes = sys.argv[1], int(sys.argv[2]), sys.argv[3].split(",")
for scene in ("dam_break_2d", "block_3d", "tank_fill_3d"):
    print(f"\n{scene} (medians of {runs} runs)\n")
    print("| mode | ms/step | vs standard | lists rebuilt per step | entries written per step | missed pairs (audit) |")
    print("| --- | ---: | ---: | ---: | ---: | ---: |")
    ms = {}
    for m in modes:
        walls = []
        for r in range(1, runs + 1):
            s = json.load(open(f"{out}/{scene}.{m}.{r}/summary.json"))
            walls.append(s["wall_seconds"] / s["steps"] * 1e3)
        ms[m] = statistics.median(walls)
    for m in modes:
        rows = list(csv.DictReader(open(f"{out}/{scene}.{m}.audit/stats.csv")))
        rebuilt = sum(int(x["lists_rebuilt"]) for x in rows) / sum(int(x["particles"]) for x in rows)
        entries = sum(int(x["entries_rebuilt"]) for x in rows) / len(rows)
        missed = sum(int(x["missed_pairs"]) for x in rows)
        print(f"| {m} | {ms[m]:.3f} | {ms['standard'] / ms[m]:.2f}x | {100 * rebuilt:.1f} % | {entries:,.0f} | {missed:,} |")
PY
