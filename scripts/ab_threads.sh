#!/usr/bin/env bash
# Two sph binaries side by side on the paper's three scenes, with 1 and 2 threads: each run's
# wall seconds (summary.json), the runs interleaved, medians of REPEATS, and each binary's
# 2-thread speed-up. Checks that both binaries end each run in the same state (kinetic energy
# and maximum speed of summary.json, bit for bit). docs/performance.md, "Static chunk schedule".
#   bash scripts/ab_threads.sh SPH_A SPH_B [REPEATS]      (default 3)
set -euo pipefail
cd "$(dirname "$0")/.."
[ $# -ge 2 ] || { echo "usage: $0 SPH_A SPH_B [REPEATS]" >&2; exit 2; }
a=$(readlink -f "$1")
b=$(readlink -f "$2")
repeats=${3:-3}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for ((r = 1; r <= repeats; r++)); do
  for s in dam_break_2d block_3d tank_fill_3d; do
    for t in 1 2; do
      for which in a b; do
        bin=$a
        [ "$which" = b ] && bin=$b
        "$bin" run "scenes/paper/$s.json" --threads "$t" --every 0 --no-progress -o "$out/run" >/dev/null 2>&1
        python3 - "$out/run/summary.json" "$s" "$t" "$which" >>"$out/times.txt" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
print(sys.argv[2], sys.argv[3], sys.argv[4], s["wall_seconds"], repr(s["kinetic_energy"]), repr(s["max_speed"]))
PY
      done
    done
  done
done
python3 - "$out/times.txt" "$repeats" <<'PY'
import collections, statistics, sys
wall, state = collections.defaultdict(list), collections.defaultdict(set)
for line in open(sys.argv[1]):
    scene, t, which, w, ke, vmax = line.split()
    wall[(scene, int(t), which)].append(float(w))
    state[(scene, int(t))].add((ke, vmax))
print(f"medians of {sys.argv[2]} runs, wall seconds")
print("| scene | A, 1 thread | A, 2 threads | A speed-up | B, 1 thread | B, 2 threads | B speed-up | B/A, 2 threads |")
print("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
for scene in ("dam_break_2d", "block_3d", "tank_fill_3d"):
    m = {k[1:]: statistics.median(v) for k, v in wall.items() if k[0] == scene}
    print(f"| {scene} | {m[(1, 'a')]:.2f} | {m[(2, 'a')]:.2f} | {m[(1, 'a')] / m[(2, 'a')]:.2f}x | {m[(1, 'b')]:.2f} | "
          f"{m[(2, 'b')]:.2f} | {m[(1, 'b')] / m[(2, 'b')]:.2f}x | {m[(2, 'a')] / m[(2, 'b')]:.2f}x |")
same = all(len(v) == 1 for v in state.values())
print("same final state in every run:", "yes" if same else "NO")
sys.exit(0 if same else 1)
PY
