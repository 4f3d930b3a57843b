#!/usr/bin/env bash
# The pictures in README.md: one rendered frame of each paper scene (docs/img/readme/*.png).
# Run after scripts/build.sh; takes about half a minute on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
sph=${SPH:-./build/sph}  # SPH=path/to/sph to use another build
out=out/readme
img=docs/img/readme
mkdir -p "$img"

$sph run scenes/paper/dam_break_2d.json -o $out/dam_break_2d --no-progress
$sph render $out/dam_break_2d --frames 20 --size 960x480 -o $out/dam_break_2d/render --no-progress
cp $out/dam_break_2d/render/frame_000020.png $img/dam_break_2d.png

$sph run scenes/paper/block_3d.json -o $out/block_3d --no-progress
$sph render $out/block_3d --frames 30 --size 960x540 -o $out/block_3d/render --no-progress
cp $out/block_3d/render/frame_000030.png $img/block_3d.png

$sph run scenes/paper/tank_fill_3d.json -o $out/tank_fill_3d --no-progress
$sph render $out/tank_fill_3d --frames last --size 960x540 --color-by density -o $out/tank_fill_3d/render --no-progress
cp "$(ls $out/tank_fill_3d/render/frame_*.png | tail -1)" $img/tank_fill_3d.png
echo "readme_pictures: wrote $img/dam_break_2d.png, $img/block_3d.png, $img/tank_fill_3d.png"
