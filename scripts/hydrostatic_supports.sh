#!/usr/bin/env bash
# The hydrostatic tanks (2D and 3D) with boundary particles and the cubic spline on several
# kernel supports: `sph validate --cases hydrostatic` on copies of the tank scenes, one line per
# support with each tank's worst interior depth bin, |p / (rho0 g d) - 1| (docs/validation.md,
# "Boundaries"). Two supports run at a time, one thread each.
#   bash scripts/hydrostatic_supports.sh SPH SUPPORT [SUPPORT ...]     (supports in spacings)
# e.g. bash scripts/hydrostatic_supports.sh build/sph 2 2.15 2.5
set -euo pipefail
cd "$(dirname "$0")/.."
[ $# -ge 2 ] || { echo "usage: $0 SPH SUPPORT [SUPPORT ...]" >&2; exit 2; }
sph=$(readlink -f "$1")
shift
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
one() {
  local support=$1 dir=$out/$1
  mkdir -p "$dir/scenes"
  cp scenes/validation/*.json "$dir/scenes/"
  python3 - "$dir/scenes" "$support" <<'PY'
import json, sys
for dim in (2, 3):
    path = f"{sys.argv[1]}/hydrostatic_{dim}d.json"
    scene = json.load(open(path))
    c = scene["Configuration"]
    c["boundaryHandling"] = "particles"
    c["kernel"] = "cubic"
    c["kernelRadius"] = round(float(sys.argv[2]) * 2 * c["particleRadius"], 12)
    json.dump(scene, open(path, "w"), indent=1)
PY
  "$sph" validate --cases hydrostatic --scenes "$dir/scenes" -o "$dir/run" --threads 1 --no-progress \
    >"$dir/log" 2>&1 || true
  local e2 e3
  e2=$(sed -n 's/.*2D: max |p \/ (rho0 g d) - 1| over depth bins below 2 layers = \([0-9.e+-]*\).*/\1/p' "$dir/log")
  e3=$(sed -n 's/.*3D: max |p \/ (rho0 g d) - 1| over depth bins below 2 layers = \([0-9.e+-]*\).*/\1/p' "$dir/log")
  echo "support $support spacings: 2D ${e2:-failed}, 3D ${e3:-failed}" >"$dir/line"
}
export -f one
export out sph
printf '%s\n' "$@" | xargs -P2 -I{} bash -c 'one {}'
for support in "$@"; do cat "$out/$support/line"; done
