#!/usr/bin/env bash
# How long idle OpenMP threads should spin before they sleep (GOMP_SPINCOUNT), measured on the
# paper's 2D dam break (1,000 steps) and tank (to its end) with 2 threads, on idle cores and with
# a busy loop competing for a core, against 1 thread. Prints medians of REPEATS runs (wall
# seconds from summary.json; runs interleaved). docs/performance.md, "How idle threads wait".
# "default" among the SPINCOUNTS runs sph with neither variable set (its own calibrated count).
#   bash scripts/spin_counts.sh SPH [REPEATS] [SPINCOUNTS]   (defaults: 3, "default 1000 10000 30000")
set -euo pipefail
cd "$(dirname "$0")/.."
[ $# -ge 1 ] || { echo "usage: $0 SPH [REPEATS] [SPINCOUNTS]" >&2; exit 2; }
sph=$(readlink -f "$1")
repeats=${2:-3}
read -r -a spins <<<"${3:-default 1000 10000 30000}"
out=$(mktemp -d)
hog=""
cleanup() {
  [ -n "$hog" ] && kill "$hog" 2>/dev/null
  rm -rf "$out"
}
trap cleanup EXIT
run() {  # scene threads setting load
  local args=(run "scenes/paper/$1.json" --threads "$2" --every 0 --no-progress -o "$out/run" --overwrite)
  [ "$1" = dam_break_2d ] && args+=(--steps 1000)
  if [ "$3" = default ]; then
    env -u GOMP_SPINCOUNT -u OMP_WAIT_POLICY "$sph" "${args[@]}" >/dev/null 2>&1
    python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["openmp_wait"])' "$out/run/summary.json" \
      >>"$out/chosen.txt"
  else
    env "$3" "$sph" "${args[@]}" >/dev/null 2>&1
  fi
  python3 -c 'import json,sys; print(sys.argv[2], json.load(open(sys.argv[1]))["wall_seconds"])' \
    "$out/run/summary.json" "$1 $2 $3 $4" >>"$out/times.txt"
}
for load in idle busy; do
  if [ "$load" = busy ]; then
    bash -c 'while :; do :; done' &
    hog=$!
  fi
  for ((r = 1; r <= repeats; r++)); do
    for s in dam_break_2d tank_fill_3d; do
      run "$s" 1 GOMP_SPINCOUNT=1000 "$load"
      for c in "${spins[@]}"; do
        if [ "$c" = default ]; then run "$s" 2 default "$load"; else run "$s" 2 "GOMP_SPINCOUNT=$c" "$load"; fi
      done
      run "$s" 2 OMP_WAIT_POLICY=passive "$load"
    done
  done
  if [ -n "$hog" ]; then kill "$hog"; hog=""; fi
done
[ -f "$out/chosen.txt" ] && echo "sph's default chose: $(sort "$out/chosen.txt" | uniq -c | tr -s ' \n' ' ')"
python3 - "$out/times.txt" "$repeats" <<'PY'
import collections, statistics, sys
t = collections.defaultdict(list)
for line in open(sys.argv[1]):
    scene, threads, setting, load, wall = line.split()
    t[(scene, load, int(threads), setting)].append(float(wall))
print(f"medians of {sys.argv[2]} runs, wall seconds (2-thread speed-up over 1 thread)")
settings = sorted({k[3] for k in t if k[2] == 2},
                  key=lambda s: (s != "default", s.startswith("OMP"), int(s.split("=")[1]) if s[0] == "G" else 0))
print("| scene | cores | 1 thread | " + " | ".join(f"2 threads, {s}" for s in settings) + " |")
print("| --- | --- | ---: | " + " | ".join("---:" for _ in settings) + " |")
for scene in ("dam_break_2d", "tank_fill_3d"):
    for load in ("idle", "busy"):
        one = statistics.median(t[(scene, load, 1, "GOMP_SPINCOUNT=1000")])
        cells = []
        for s in settings:
            m = statistics.median(t[(scene, load, 2, s)])
            cells.append(f"{m:.2f} ({one / m:.2f}x)")
        print(f"| {scene} | {load} | {one:.2f} | " + " | ".join(cells) + " |")
PY
