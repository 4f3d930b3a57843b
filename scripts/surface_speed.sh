#!/usr/bin/env bash
# Surface speed (docs/performance.md, "Surfaces"): sph surface on a 1M-particle 3D dam break
# (100^3 particles, spacing 0.01 m; frames at steps 0 and 200, 400), meshing only (PLY) and with
# every file, REPEATS times for 1 and 2 threads; then OpenVDB's own particle surfacing
# (scripts/surface_bench) on a 100^3 lattice at 1 and 2 voxels per spacing.
#   bash scripts/surface_speed.sh [REPEATS] [OUT_DIR]     (after bash scripts/build.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
repeats=${1:-3}
out=${2:-/tmp/surface_speed}
mkdir -p "$out"
scene="$out/dam_break_1m.json"
cat >"$scene" <<'JSON'
{
  "version": 1, "name": "dam_break_1m", "dimension": 3,
  "description": "A 3D dam break of 1,000,000 particles (100^3, spacing 0.01 m) for the surface benchmark.",
  "Configuration": {"precision": "float", "timeStepSize": 2e-4, "numberOfSteps": 400, "particleRadius": 0.005,
                    "kernelRadius": 0.02, "gravitation": [0, -9.81, 0], "neighbors": "standard",
                    "boundaryHandling": "penalty", "outputEveryNSteps": 200},
  "Fluid": {"density0": 1000, "stiffness": 900, "viscosity": 3.0, "negativePressure": "clamp"},
  "Container": {"start": [0, 0, 0], "end": [3.0, 1.5, 1.0], "wallStiffness": 4e5, "wallDamping": 300},
  "FluidBlocks": [{"start": [0, 0, 0], "end": [1.0, 1.0, 1.0]}]
}
JSON
[ -f "$out/run/frames/frame_000002.vtu" ] || ./build/sph run "$scene" -o "$out/run" --threads 2 --no-progress
for t in 1 2; do
  for format in ply all; do
    for r in $(seq "$repeats"); do
      /usr/bin/time -f "wall %e s" ./build/sph surface "$out/run" --frames 2 --format $format --threads $t \
        --no-progress -o "$out/surface_$t" 2>&1 | grep -E "done|wall" | tr '\n' ' ' | sed "s/^/threads $t format $format: /"
      echo
    done
  done
done
cmake -S scripts/surface_bench -B "$out/openvdb_build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$out/openvdb_build" >/dev/null
for t in 1 2; do
  for res in 1 2; do echo "openvdb threads $t res $res: $("$out/openvdb_build/openvdb_particles" 100 $res 1 $t)"; done
done
