#!/usr/bin/env bash
# The pair loops' arithmetic with contiguous loads against gathers, on one core, from cache
# (scripts/pair_bound.cpp; docs/performance.md, "The pair loops against the machine").
# Built with the project's flags (-O3 -march=native -ffp-contract=off -fno-math-errno).
#   bash scripts/pair_bound.sh [RUNS]      (RUNS runs, default 5; each prints one line per precision)
set -euo pipefail
cd "$(dirname "$0")/.."
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
"${CXX:-g++}" -std=c++20 -O3 -march=native -ffp-contract=off -fno-math-errno -Isrc scripts/pair_bound.cpp -o "$out/pair_bound"
for _ in $(seq "${1:-5}"); do "$out/pair_bound"; done
