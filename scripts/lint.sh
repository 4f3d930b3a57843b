#!/usr/bin/env bash
# The project's rules checked (scripts/test.sh runs this, and so CI): the layer order of the
# includes (check_layers.py), the format (check_format.sh) and clang-tidy's naming and bug
# checks (check_tidy.sh, with build/compile_commands.json: build first). Runs all three and
# exits 1 if any failed. Usage: bash scripts/lint.sh [BUILD_DIR]
set -uo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
failed=()
t0=$SECONDS
python3 scripts/check_layers.py || failed+=(layers)
bash scripts/check_format.sh || failed+=(format)
bash scripts/check_tidy.sh "$build" || failed+=(tidy)
if [ ${#failed[@]} -ne 0 ]; then
  echo "lint: FAILED: ${failed[*]} ($((SECONDS - t0)) s)"
  exit 1
fi
echo "lint: layers, format and tidy pass ($((SECONDS - t0)) s)"
