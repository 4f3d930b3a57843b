#!/usr/bin/env bash
# The physics corpus (tests/app/trust/) under both boundary handlings: runs every scene that is
# not refused with Configuration.boundaryHandling "penalty" and "particles" and prints, per scene,
# each run's status (completed / warned / failed and why), then how many of each per handling
# (docs/validation.md, "Boundaries": the choice of the default).
#   bash scripts/trust_boundaries.sh SPH
set -euo pipefail
cd "$(dirname "$0")/.."
sph=$(readlink -f "$1")
out=$(mktemp -d)
declare -A count
for scene in tests/app/trust/*.json; do
  name=$(basename "$scene" .json)
  grep -q '^verdict: refused' "tests/app/trust/$name.expect" && continue
  args=$(sed -n 's/^args: //p' "tests/app/trust/$name.expect")
  line="$name"
  for b in penalty particles; do
    # shellcheck disable=SC2086
    "$sph" run "$scene" -o "$out/$name.$b" --no-progress --set Configuration.boundaryHandling=$b $args \
      >/dev/null 2>&1 || true
    status=$(python3 -c "import json,sys;print(json.load(open(sys.argv[1]))['status'])" "$out/$name.$b/summary.json" \
      2>/dev/null || echo "refused")
    kind=${status%%:*}
    count[$b,$kind]=$((${count[$b,$kind]:-0} + 1))
    line="$line | $b: ${status:0:110}"
  done
  echo "$line"
done
for b in penalty particles; do
  echo "$b: ${count[$b,completed]:-0} completed, ${count[$b,completed with warnings]:-0} warned, ${count[$b,failed]:-0} failed, ${count[$b,refused]:-0} refused"
done
rm -rf "$out"
