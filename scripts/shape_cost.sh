#!/usr/bin/env bash
# What an obstacle of any shape costs (docs/performance.md, "Mesh and polygon obstacles"): a 3D dam
# break (14,400 particles, 200 steps, 2 threads) onto an obstacle 0.2 m x 0.3 m x
# 0.2 m standing on the floor, given as a box and as a mesh of the same box (tests/data/meshes/cube.obj
# scaled; 12 triangles), and as the boulder of scenes/examples (5,120 triangles, about the same
# size), with penalty walls (the mesh's signed distance every step, for the particles near it) and
# with boundary particles (DFSPH, fixed 2 ms steps; the mesh only when sampling, at the start).
# The penalty runs take the scene's "auto" step. RUNS times each (default 3),
# alternating; prints each run's ms/step and the setup time (wall time less the steps').
#   bash scripts/shape_cost.sh [SPH] [RUNS]
set -euo pipefail
cd "$(dirname "$0")/.."
sph=$(readlink -f "${1:-build/sph}") runs=${2:-3}
root=$(pwd)
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
scene() {  # boundary handling, obstacle JSON
  local method='"boundaryHandling": "penalty"'
  [ "$1" = particles ] && method='"boundaryHandling": "particles", "kernel": "cubic", "simulationMethod": "dfsph", "timeStepSize": 0.002, "cflMethod": "none"'
  cat <<JSON
{ "version": 1, "name": "shape_cost", "dimension": 3,
  "Configuration": { "precision": "float", "numberOfSteps": 200, "particleRadius": 0.01, "kernelRadius": 0.04,
    "gravitation": [0, -9.81, 0], "outputEveryNSteps": 0, $method },
  "Fluid": { "density0": 1000 },
  "Container": { "start": [0, 0, 0], "end": [1.0, 0.6, 0.4] },
  "FluidBlocks": [ { "start": [0, 0, 0], "end": [0.3, 0.48, 0.4] } ],
  "Obstacles": [ $2 ] }
JSON
}
for b in penalty particles; do
  scene $b '{ "start": [0.6, 0, 0.1], "end": [0.8, 0.3, 0.3] }' >"$dir/box_$b.json"
  scene $b "{ \"geometryFile\": \"$root/tests/data/meshes/cube.obj\", \"scale\": [0.2, 0.3, 0.2], \"translation\": [0.6, 0, 0.1] }" >"$dir/mesh_$b.json"
  scene $b "{ \"geometryFile\": \"$root/scenes/examples/meshes/boulder.obj\", \"scale\": [0.65, 1.6, 0.85], \"translation\": [0.7, 0, 0.2] }" >"$dir/boulder_$b.json"
done
for k in $(seq "$runs"); do
  for b in penalty particles; do
    for c in box mesh boulder; do
      start=$(date +%s.%N)
      out=$(OMP_WAIT_POLICY=passive "$sph" run "$dir/${c}_$b.json" -o "$dir/out_${c}_$b" --overwrite --no-progress \
        --threads 2 2>&1) || { echo "shape_cost: $c ($b) failed: $out" >&2; exit 1; }
      line=$(grep -o "done.*ms/step)" <<<"$out")
      end=$(date +%s.%N)
      python3 - "$c" "$b" "$k" "$start" "$end" "$line" <<'PY'
import re, sys
c, b, k, start, end, line = sys.argv[1:]
m = re.search(r"([0-9.]+) s \(([0-9.]+) ms/step\)", line)
steps_s, ms = float(m.group(1)), float(m.group(2))
print(f"{b:9s} {c:7s} run {k}: {ms:7.3f} ms/step, setup and output {float(end) - float(start) - steps_s:5.2f} s")
PY
    done
  done
done
