#!/usr/bin/env bash
# Checks that two sph binaries write bitwise-identical frames: every paper and validation scene
# for a short run (120 steps, a frame every 40) in the standard and adaptive modes, in every
# frame format (vtu, vtk, ply), then compares the sha256 of every frame file (frames/frame_*: the
# obstacles' surfaces beside them, frames/solids_*, are not compared).
#   bash scripts/frames_identical.sh OLD_SPH NEW_SPH [OUT_DIR]
# Exits 0 if every frame matches, 1 (listing the differing files) otherwise. Used for changes
# that must not change results (e.g. a refactoring: build the starting commit's sph, then yours).
set -euo pipefail
cd "$(dirname "$0")/.."
[ $# -ge 2 ] || { echo "usage: bash scripts/frames_identical.sh OLD_SPH NEW_SPH [OUT_DIR]" >&2; exit 2; }
old=$(readlink -f "$1") new=$(readlink -f "$2") out=${3:-$(mktemp -d)}
for b in "$old" "$new"; do [ -x "$b" ] || { echo "frames_identical: $b is not an executable" >&2; exit 2; }; done
run_all() {  # binary, directory
  rm -rf "$2"
  mkdir -p "$2"
  for scene in scenes/paper/*.json scenes/validation/*.json scenes/validation/*/*.json; do
    name=$(echo "${scene#scenes/}" | tr / _)
    name=${name%.json}
    for mode in standard adaptive; do
      "$1" run "$scene" --steps 120 --neighbors $mode --format vtu,vtk,ply --every 40 --threads 2 \
        -o "$2/$name.$mode" --no-progress >/dev/null 2>"$2/$name.$mode.err" ||
        { echo "frames_identical: $1 failed on $scene ($mode); see $2/$name.$mode.err" >&2; exit 1; }
    done
  done
  (cd "$2" && find . -path '*/frames/frame_*' -type f | sort | xargs sha256sum) >"$2.sums"
}
run_all "$old" "$out/old"
run_all "$new" "$out/new"
if diff "$out/old.sums" "$out/new.sums" >"$out/diff.txt"; then
  echo "frames_identical: all $(wc -l <"$out/new.sums") frame files identical ($out)"
else
  echo "frames_identical: frames differ ($out/diff.txt):"
  head -20 "$out/diff.txt"
  exit 1
fi
