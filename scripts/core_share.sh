#!/usr/bin/env bash
# Whether two threads share a core's arithmetic or caches on this machine (scripts/core_share.cpp;
# docs/performance.md, "The density sums' room, two list-build tries, and the tank on two threads").
#   bash scripts/core_share.sh [RUNS]      (RUNS runs, default 3; each prints four lines)
exec bash "$(dirname "$0")/probe.sh" core_share "${1:-3}"
