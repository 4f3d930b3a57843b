#!/usr/bin/env bash
# Installs what is missing, builds, and runs the whole test suite, then again under sanitizers.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh
# Tests run in parallel and each may use every core: idle OpenMP threads must sleep, not spin,
# or oversubscribed cores slow the suite down tenfold.
OMP_WAIT_POLICY=passive ctest --test-dir build --output-on-failure -j "$(nproc)"
# The suite again under AddressSanitizer + UndefinedBehaviorSanitizer, its parallel parts under
# ThreadSanitizer, and a minute of fuzzing the scene reader (build-asan, build-tsan, build-fuzz).
bash scripts/sanitize.sh
