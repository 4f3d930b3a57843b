#!/usr/bin/env bash
# Resident memory over a long run: the 2D dam break (3,200 particles) for STEPS steps (default
# 100,000) in each neighbor mode, with a checkpoint every 10,000 steps and a frame every 5,000.
# Samples the process's VmRSS every 0.2 s and prints, per mode, the resident memory after the
# first 10 % of the run, at the end, and the largest, in a Markdown table (docs/reliability.md).
#
#   bash scripts/long_run_memory.sh [OUT_DIR] [STEPS]      (about 2 minutes per mode on 2 cores)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/long_run_memory}
steps=${2:-100000}
sph=${SPH:-build/sph}
[ -x "$sph" ] || { echo "long_run_memory: $sph not found; run scripts/build.sh first" >&2; exit 2; }
mkdir -p "$out"

for mode in standard adaptive verlet; do
  samples="$out/rss_$mode.csv"
  echo "ms,rss_kib" >"$samples"
  "$sph" run scenes/paper/dam_break_2d.json --neighbors "$mode" --steps "$steps" --checkpoint-every 10000 \
    --set Configuration.outputEveryNSteps=5000 --no-progress -o "$out/run_$mode" 2>"$out/run_$mode.log" &
  pid=$!
  start=$(date +%s%N)
  while kill -0 "$pid" 2>/dev/null; do
    rss=$(awk '/^VmRSS:/ {print $2}' "/proc/$pid/status" 2>/dev/null || true)
    [ -n "$rss" ] && echo "$((($(date +%s%N) - start) / 1000000)),$rss" >>"$samples"
    sleep 0.2
  done
  wait "$pid" || { echo "long_run_memory: the $mode run failed; see $out/run_$mode.log" >&2; exit 1; }
done

python3 - "$out" "$steps" <<'EOF'
import csv, sys
out, steps = sys.argv[1], int(sys.argv[2])
print(f"| mode | steps | samples | RSS after 10 % of the run (MiB) | RSS at the end (MiB) | largest RSS (MiB) | growth after 10 % |")
print("| --- | --- | --- | --- | --- | --- | --- |")
for mode in ("standard", "adaptive", "verlet"):
    rows = [(float(r["ms"]) / 1e3, int(r["rss_kib"])) for r in csv.DictReader(open(f"{out}/rss_{mode}.csv"))]
    if len(rows) < 10:
        print(f"| {mode} | {steps} | {len(rows)} | (too few samples) | | | |")
        continue
    t_end = rows[-1][0]
    after = [r for r in rows if r[0] >= 0.1 * t_end]
    first, last, peak = after[0][1], rows[-1][1], max(r[1] for r in rows)
    grow = max(r[1] for r in after) - first
    print(f"| {mode} | {steps} | {len(rows)} | {first / 1024:.1f} | {last / 1024:.1f} | {peak / 1024:.1f} | "
          f"{grow / 1024:+.2f} MiB |")
EOF
