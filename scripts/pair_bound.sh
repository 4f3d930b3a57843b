#!/usr/bin/env bash
# The pair loops' arithmetic with contiguous loads against gathers, on one core, from cache
# (scripts/pair_bound.cpp; docs/performance.md, "The pair loops against the machine").
#   bash scripts/pair_bound.sh [RUNS]      (RUNS runs, default 5; each prints one line per precision)
exec bash "$(dirname "$0")/probe.sh" pair_bound "${1:-5}"
