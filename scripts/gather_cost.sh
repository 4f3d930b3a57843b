#!/usr/bin/env bash
# A register of neighbors' values by gathers against simd::gather_vectors, on one core
# (scripts/gather_cost.cpp; docs/performance.md, "Neighbors' values loaded, not gathered").
#   bash scripts/gather_cost.sh [RUNS]      (RUNS runs, default 3; each prints four lines)
exec bash "$(dirname "$0")/probe.sh" gather_cost "${1:-3}"
