#!/usr/bin/env bash
# The cost of boundary particles against penalty walls on one scene: runs it with
# Configuration.boundaryHandling "penalty" and "particles", alternately, REPEATS times each, and
# prints the boundary samples per fluid particle and the median wall ms per step of the steps
# after the first WARM (stats.csv's phase times), with their ratio (docs/performance.md).
#   bash scripts/boundary_cost.sh SPH SCENE STEPS [WARM] [REPEATS] [--set KEY=VALUE ...]
set -euo pipefail
[ $# -ge 3 ] || { echo "usage: bash scripts/boundary_cost.sh SPH SCENE STEPS [WARM] [REPEATS] [--set ...]" >&2; exit 2; }
sph=$1 scene=$2 steps=$3 warm=${4:-2} repeats=${5:-3}
shift $(($# < 5 ? $# : 5))
out=$(mktemp -d)
for r in $(seq "$repeats"); do
  for b in penalty particles; do
    "$sph" run "$scene" -o "$out/$b.$r" --steps "$steps" --no-progress --set Configuration.outputEveryNSteps=0 \
      --set Configuration.boundaryHandling=$b "$@" >/dev/null
  done
done
python3 - "$out" "$repeats" "$warm" <<'PY'
import csv, json, statistics, sys
out, repeats, warm = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
ms = {}
for b in ("penalty", "particles"):
    runs = []
    for r in range(1, repeats + 1):
        rows = list(csv.DictReader(open(f"{out}/{b}.{r}/stats.csv")))[warm:]
        runs.append(1000 * statistics.mean(sum(float(row[c]) for c in ("t_grid", "t_lists", "t_density", "t_forces", "t_integrate")) for row in rows))
    s = json.load(open(f"{out}/{b}.1/summary.json"))
    ms[b] = statistics.median(runs)
    print(f"{b:9s} particles {s['particles']:>9,}  boundary samples {s['boundary_samples']:>9,} "
          f"({s['boundary_samples'] / s['particles']:.2f} per fluid particle)  ms/step median {ms[b]:.3f} "
          f"[{min(runs):.3f} .. {max(runs):.3f}]")
print(f"particles / penalty step time: {ms['particles'] / ms['penalty']:.2f}")
PY
rm -rf "$out"
