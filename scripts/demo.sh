#!/usr/bin/env bash
# The main job for a new user: install, build, run the paper's 2D dam break (Fig. 2) and make
# something to look at.
# Output in out/dam_break_2d/: frames.pvd (ParaView), render/frame_*.png and render/movie.mp4
# (sph render), view.html (sph view: open it in a browser), stats.csv, summary.json.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh
./build/sph run scenes/paper/dam_break_2d.json -o out/dam_break_2d
./build/sph render out/dam_break_2d --mp4
./build/sph view out/dam_break_2d
