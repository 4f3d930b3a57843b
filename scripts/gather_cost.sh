#!/usr/bin/env bash
# A register of neighbors' values by gathers against simd::gather_vectors, on one core
# (scripts/gather_cost.cpp; docs/performance.md, "Neighbors' values loaded, not gathered").
# Built with the project's flags (-O3 -march=native -ffp-contract=off -fno-math-errno).
#   bash scripts/gather_cost.sh [RUNS]      (RUNS runs, default 3; each prints four lines)
set -euo pipefail
cd "$(dirname "$0")/.."
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
"${CXX:-g++}" -std=c++20 -O3 -march=native -ffp-contract=off -fno-math-errno -Isrc scripts/gather_cost.cpp -o "$out/gather_cost"
for _ in $(seq "${1:-3}"); do "$out/gather_cost"; done
