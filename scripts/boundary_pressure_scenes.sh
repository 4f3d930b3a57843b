#!/usr/bin/env bash
# DFSPH's boundary pressures on every DFSPH scene but the validation's (docs/physics.md, "DFSPH",
# "Boundaries"): each scene run whole with Configuration.boundaryPressure "none" and
# "extrapolate", no frames; prints per run the steps, the mean step and density-solve
# iterations, the 99th percentile over the steps of the densest particle (rho_max / rho0), the
# mean density error and the kinetic energy at the end.
#   bash scripts/boundary_pressure_scenes.sh [SPH] [OUT]
set -euo pipefail
cd "$(dirname "$0")/.."
sph=${1:-build/sph} out=${2:-out/boundary_pressure}
mkdir -p "$out"
for s in scenes/dfsph/*.json $(grep -l '"dfsph"' scenes/examples/*.json); do
  n=$(basename "$s" .json)
  for bp in none extrapolate; do
    "$sph" run "$s" --set Configuration.boundaryPressure="$bp" --every 0 --no-progress --overwrite \
      -o "$out/$n-$bp" >/dev/null
  done
done
python3 - "$out" <<'PY'
import csv, glob, os, sys
out = sys.argv[1]
print("| scene | boundaryPressure | steps | mean dt (ms) | iterations | rho_max / rho0, 99th pct | density error (%) | KE at the end (J) |")
print("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |")
for d in sorted(glob.glob(os.path.join(out, "*-none"))):
    n = os.path.basename(d)[: -len("-none")]
    for bp in ("none", "extrapolate"):
        rows = list(csv.DictReader(open(os.path.join(out, f"{n}-{bp}", "stats.csv"))))
        mean = lambda k: sum(float(r[k]) for r in rows) / len(rows)
        peaks = sorted(float(r["rho_max"]) for r in rows)
        print(f"| {n} | {bp} | {len(rows)} | {1e3 * mean('dt'):.2f} | {mean('solver_iterations'):.1f} | "
              f"{peaks[int(0.99 * len(peaks))]:.3f} | {mean('density_error'):.4f} | {float(rows[-1]['kinetic_energy']):.3g} |")
PY
