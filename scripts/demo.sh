#!/usr/bin/env bash
# The main job for a new user: install, build, and run the paper's 2D dam break (Fig. 2).
# Output: out/dam_break_2d/ (frames.pvd for ParaView, stats.csv, summary.json).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh
./build/sph run scenes/paper/dam_break_2d.json -o out/dam_break_2d
