#!/usr/bin/env bash
# The surface pictures of docs/visualization.md ("Surfaces"): each paper scene run, then
# `sph render --surface` of one frame into docs/img/surface/. Usage (after bash scripts/build.sh):
#   bash scripts/surface_pictures.sh [OUT_DIR]     (runs go to OUT_DIR, default out/surface_pictures)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/surface_pictures}
img=docs/img/surface
mkdir -p "$out" "$img"
for spec in block_3d:30 tank_fill_3d:-1 dam_break_2d:20; do
  scene=${spec%%:*} frame=${spec#*:}
  ./build/sph run "scenes/paper/$scene.json" -o "$out/$scene" --no-progress >/dev/null
  ./build/sph render "$out/$scene" --surface --frames "$frame" --size 960x540 -o "$out/$scene/render_surface" \
    --no-progress >/dev/null
  cp "$out/$scene/render_surface/"frame_*.png "$img/$scene.png"
  echo "$img/$scene.png: frame $frame of $scene"
done
