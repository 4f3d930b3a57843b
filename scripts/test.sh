#!/usr/bin/env bash
# Installs what is missing, builds, runs the whole test suite, checks the project's rules and
# its install, then runs the suite again under sanitizers. CI (.ci/run) runs exactly this.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh
# Tests run in parallel and each may use every core: idle OpenMP threads must sleep, not spin,
# or oversubscribed cores slow the suite down tenfold.
OMP_WAIT_POLICY=passive ctest --test-dir build --output-on-failure -j "$(nproc)"
# The rules: includes one way along the layers, the format, clang-tidy's naming and bug checks.
bash scripts/lint.sh build
# cmake --install into a prefix, moved: the installed sph validate and bench find their scenes,
# and a find_package(sph) project builds against it.
bash scripts/check_install.sh build
# The suite again under AddressSanitizer + UndefinedBehaviorSanitizer (portable build: the
# scalar paths), its parallel parts under ThreadSanitizer, and a minute of fuzzing the scene
# reader (build-asan, build-tsan, build-fuzz).
bash scripts/sanitize.sh
