#!/usr/bin/env bash
# The tracked mode's skin sweep of docs/neighbor-modes.md ("Choosing the skin"): the paper's 3D
# block and 2D dam break in `tracked` with fixed skins of 0.02, 0.05, 0.1 and 0.2 h and with the
# automatic skin, REPEATS runs of each (interleaved), 2 threads, frames off. Prints, per skin, the
# median over the runs of the sum of the grid, list, density and force timers of stats.csv
# (seconds, with the fastest and slowest run), the share of lists rebuilt per step (the same in
# every run) and, for the automatic skin, the range of stats.csv's skin column in units of h.
#
#   bash scripts/skin_sweep.sh [SPH] [REPEATS] [OUT]     (defaults: build/sph 3 out/skin_sweep)
set -euo pipefail
sph=${1:-build/sph}
repeats=${2:-3}
out=${3:-out/skin_sweep}
mkdir -p "$out"
skins=(0.02 0.05 0.1 0.2 auto)
scenes=(block_3d dam_break_2d)
for ((r = 1; r <= repeats; r++)); do
  for f in "${skins[@]}"; do
    for s in "${scenes[@]}"; do
      h=$(python3 -c "import json; print(json.load(open('scenes/paper/$s.json'))['Configuration']['kernelRadius'])")
      set_skin=()
      [ "$f" = auto ] || set_skin=(--set "Configuration.trackedSkin=$(python3 -c "print($f * $h)")")
      "$sph" run "scenes/paper/$s.json" --neighbors tracked --every 0 --no-progress --threads 2 \
        "${set_skin[@]}" -o "$out/${s}_${f}_$r" >/dev/null
    done
  done
done
python3 - "$out" "$repeats" "${skins[@]}" <<'PY'
import csv, json, statistics, sys
out, repeats, skins = sys.argv[1], int(sys.argv[2]), sys.argv[3:]
scenes = ["block_3d", "dam_break_2d"]
def run(path):
    rows = list(csv.DictReader(open(path + "/stats.csv")))
    t = sum(float(r[k]) for r in rows for k in ("t_grid", "t_lists", "t_density", "t_forces"))
    rebuilt = sum(float(r["lists_rebuilt"]) / float(r["particles"]) for r in rows) / len(rows)
    return t, rebuilt
for s in scenes:
    h = json.load(open(f"scenes/paper/{s}.json"))["Configuration"]["kernelRadius"]
    rows = list(csv.DictReader(open(f"{out}/{s}_auto_1/stats.csv")))
    used = [float(r["skin"]) / h for r in rows if float(r["skin"]) > 0]
    print(f"{s}: the automatic skin is {min(used):.3f} h to {max(used):.3f} h")
print("| skin | block 3D: grid + lists + density + forces | lists rebuilt per step "
      "| 2D dam break: same sum | lists rebuilt per step |")
print("| --- | ---: | ---: | ---: | ---: |")
for f in skins:
    cells = []
    for s in scenes:
        runs = [run(f"{out}/{s}_{f}_{r}") for r in range(1, repeats + 1)]
        times = sorted(t for t, _ in runs)
        cells += [f"{statistics.median(times):.2f} s ({times[0]:.2f}-{times[-1]:.2f})", f"{100 * runs[0][1]:.1f} %"]
    print(f"| {'automatic' if f == 'auto' else f + ' h'} | " + " | ".join(cells) + " |")
PY
