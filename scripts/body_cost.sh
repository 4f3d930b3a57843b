#!/usr/bin/env bash
# What a floating body's two-way coupling costs a step (docs/performance.md, "Floating bodies'
# coupling"): a 2D box of density 500 dropped onto water (4,800 particles, DFSPH, boundary
# particles, fixed 2 ms steps, 250 steps) against the same box on a prescribed oscillation, RUNS
# times each (default 3), alternating; prints each run's ms/step and the phases' mean times. With
# a second binary OTHER, each run of each scene is made with both, one after the other.
#   bash scripts/body_cost.sh [SPH] [RUNS] [OTHER]
set -euo pipefail
cd "$(dirname "$0")/.."
sph=${1:-build/sph} runs=${2:-3} other=${3:-}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
scene() {  # obstacle JSON
  cat <<JSON
{ "version": 1, "name": "body_cost", "dimension": 2,
  "Configuration": { "precision": "double", "timeStepSize": 0.002, "stopAt": 0.5, "cflMethod": "none",
    "particleRadius": 0.005, "kernelRadius": 0.02, "gravitation": [0, -9.81], "boundaryHandling": "particles",
    "kernel": "cubic", "simulationMethod": "dfsph", "outputFps": 0 },
  "Fluid": { "density0": 1000, "stiffness": 1600, "viscosity": 1.0 },
  "Container": { "start": [0, 0], "end": [1.2, 0.8] },
  "FluidBlocks": [ { "start": [0, 0], "end": [1.2, 0.4] } ],
  "Obstacles": [ $1 ] }
JSON
}
scene '{ "start": [0.4, 0.42], "end": [0.8, 0.62], "dynamic": true, "density": 500 }' >"$dir/floating.json"
scene '{ "start": [0.4, 0.42], "end": [0.8, 0.62], "motion": { "type": "oscillation", "direction": [0, 1], "amplitude": 0.01, "period": 1.0 } }' >"$dir/prescribed.json"
for k in $(seq "$runs"); do
  for c in floating prescribed; do
    n=0
    for b in "$sph" ${other:+"$other"}; do
      n=$((n + 1))
      OMP_WAIT_POLICY=passive "$b" run "$dir/$c.json" -o "$dir/$c-$n" --overwrite --no-progress --threads 2 2>&1 |
        grep -o "done.*ms/step)" | sed "s|^|$c run $k${other:+ ($b)}: |"
    done
  done
done
n=0
for b in "$sph" ${other:+"$other"}; do
  n=$((n + 1))
  for c in floating prescribed; do
    python3 - "$dir/$c-$n/stats.csv" "$c${other:+ ($b)}" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
mean = lambda k: sum(float(r[k]) for r in rows) / len(rows)
print(f"{sys.argv[2]} (last run): forces {1e3 * mean('t_forces'):.2f} ms, integrate {1e3 * mean('t_integrate'):.2f} ms, "
      f"solves {1e3 * mean('t_solve'):.2f} ms ({mean('solver_iterations'):.1f} iterations)")
PY
  done
done
