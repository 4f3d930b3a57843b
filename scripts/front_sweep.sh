#!/usr/bin/env bash
# The Martin & Moyce front (a/40, standard mode) under scene overrides, one line per setting:
# max and mean dZ against the experiment, and the front's slope dZ/dT for T >= 1.4 (the
# experiment's and the run's; Ritter's inviscid shallow-water front is sqrt 2 = 1.414).
# docs/validation.md, "Boundaries": the boundary friction and kernel sweep. With FRONT_VARIANT=dfsph
# the scene is martin_moyce_2d_dfsph.json, run by the dfsph case (its tanks cut to 0.02 s), and the
# column is DFSPH's (docs/validation.md, "DFSPH": the viscosity sweep).
#   bash scripts/front_sweep.sh SPH "KEY=VALUE KEY=VALUE ..." ["KEY=VALUE ..." ...]
# e.g. bash scripts/front_sweep.sh build/sph "" "Configuration.boundaryHandling=particles Configuration.kernel=cubic"
set -euo pipefail
cd "$(dirname "$0")/.."
sph=$(readlink -f "$1")
shift
variant=${FRONT_VARIANT:-}
scene=martin_moyce_2d${variant:+_$variant}.json
case_name=${variant:-martin_moyce}
column=Z_a_40_standard${variant:+_$variant}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for setting in "$@"; do
  rm -rf "$out/scenes" "$out/run"
  mkdir -p "$out/scenes"
  cp scenes/validation/*.json "$out/scenes/"
  # The overrides go into the copied scene: sph validate derives every resolution from it.
  # shellcheck disable=SC2086
  python3 - "$out/scenes/$scene" "$variant" $setting <<'PY'
import json, sys
path = sys.argv[1]
if sys.argv[2] == "dfsph":  # the dfsph case also runs its tanks: cut them short
    for d in (2, 3):
        tank = path.replace("martin_moyce_2d_dfsph", f"hydrostatic_{d}d_dfsph")
        t = json.load(open(tank))
        t["Configuration"]["stopAt"] = 0.02
        json.dump(t, open(tank, "w"), indent=1)
del sys.argv[2]
scene = json.load(open(path))
for arg in sys.argv[2:]:
    key, value = arg.split("=", 1)
    section, name = key.split(".")
    try:
        value = json.loads(value)
    except ValueError:
        pass
    scene[section][name] = value
json.dump(scene, open(path, "w"), indent=1)
PY
  "$sph" validate --cases "$case_name" --scenes "$out/scenes" -o "$out/run" --no-progress >/dev/null 2>&1 || true
  python3 - "$out/run/front_points.csv" "${setting:-(the scene as it is)}" "$column" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
T = [float(r["T"]) for r in rows]
exp = [float(r["Z_experiment"]) for r in rows]
run = [float(r[sys.argv[3]]) for r in rows]
dz = [b - a for a, b in zip(exp, run)]
def slope(xs, ys):
    pts = [(x, y) for x, y in zip(xs, ys) if x >= 1.4]
    mx = sum(p[0] for p in pts) / len(pts); my = sum(p[1] for p in pts) / len(pts)
    return sum((p[0] - mx) * (p[1] - my) for p in pts) / sum((p[0] - mx) ** 2 for p in pts)
print(f"{sys.argv[2]}: max |dZ| {max(map(abs, dz)):.3f}, mean dZ {sum(dz) / len(dz):+.3f}, "
      f"slope {slope(T, run):.3f} (experiment {slope(T, exp):.3f})")
PY
done
