#!/usr/bin/env bash
# Builds one of the stand-alone measuring programs scripts/NAME.cpp with the project's flags
# (-O3 -march=native -ffp-contract=off -fno-math-errno, src/ on the include path) and runs it RUNS
# times. pair_bound.sh, gather_cost.sh and core_share.sh call it.
#   bash scripts/probe.sh NAME [RUNS]      (RUNS default 1)
set -euo pipefail
cd "$(dirname "$0")/.."
[ $# -ge 1 ] && [ -f "scripts/$1.cpp" ] || { echo "usage: bash scripts/probe.sh NAME [RUNS] (scripts/NAME.cpp)" >&2; exit 2; }
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
"${CXX:-g++}" -std=c++20 -O3 -march=native -ffp-contract=off -fno-math-errno -Isrc "scripts/$1.cpp" -o "$out/$1"
for _ in $(seq "${2:-1}"); do "$out/$1"; done
