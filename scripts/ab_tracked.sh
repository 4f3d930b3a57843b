#!/usr/bin/env bash
# A change to one neighbor mode, measured beside the others: on the paper's three scenes, 2
# threads, SPH_A's MODE, then SPH_B's MODE, standard, adaptive, verlet and adaptive_exact, the
# runs interleaved REPEATS times. Prints each row's median ms per step (fastest and slowest in
# brackets), its speed against SPH_B's standard, and the median grid and list seconds of a run
# (summary.json's phase_seconds). docs/performance.md, "Exact adaptive pairing: the tracked modes".
#   bash scripts/ab_tracked.sh SPH_A SPH_B [REPEATS] [MODE]      (defaults: 3, tracked)
set -euo pipefail
cd "$(dirname "$0")/.."
[ $# -ge 2 ] || { echo "usage: $0 SPH_A SPH_B [REPEATS] [MODE]" >&2; exit 2; }
a=$(readlink -f "$1")
b=$(readlink -f "$2")
repeats=${3:-3}
mode=${4:-tracked}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
rows="a:$mode b:$mode b:standard b:adaptive b:verlet b:adaptive_exact"
for s in dam_break_2d block_3d tank_fill_3d; do
  for ((r = 1; r <= repeats; r++)); do
    for row in $rows; do
      bin=$a
      [ "${row%%:*}" = b ] && bin=$b
      "$bin" run "scenes/paper/$s.json" --neighbors "${row##*:}" --threads 2 -o "$out/$s.${row/:/.}.$r" \
        --every 0 --no-progress >/dev/null 2>&1
    done
  done
done
python3 - "$out" "$repeats" "$rows" <<'PY'
import json, statistics, sys
out, repeats, rows = sys.argv[1], int(sys.argv[2]), sys.argv[3].split()
print("| scene | binary: mode | ms/step | vs B's standard | grid + lists, s |")
print("| --- | --- | ---: | ---: | ---: |")
for s in ("dam_break_2d", "block_3d", "tank_fill_3d"):
    res = {}
    for row in rows:
        ms, lists = [], []
        for r in range(1, repeats + 1):
            j = json.load(open(f"{out}/{s}.{row.replace(':', '.')}.{r}/summary.json"))
            ms.append(j["wall_seconds"] / j["steps"] * 1e3)
            lists.append(j["phase_seconds"]["grid"] + j["phase_seconds"]["lists"])
        res[row] = (statistics.median(ms), min(ms), max(ms), statistics.median(lists))
    standard = res["b:standard"][0]
    for row, (ms, lo, hi, lists) in res.items():
        name = row.replace("a:", "A: ").replace("b:", "B: ")
        print(f"| {s} | {name} | {ms:.3f} [{lo:.3f}-{hi:.3f}] | {standard / ms:.2f}x | {lists:.2f} |")
PY
