#!/usr/bin/env bash
# Installs what is missing, builds, runs the whole test suite, checks the project's rules and
# its install, then runs the lower layers' tests again under sanitizers. CI (.ci/run) runs exactly this.
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
# The unit tests of the layers below io (core, neighbors, solver, scene) again under
# AddressSanitizer + UndefinedBehaviorSanitizer (portable build: the scalar paths), the parallel
# code's tests under ThreadSanitizer, and 30 s of fuzzing the scene reader (build-asan,
# build-tsan). The whole suite under the sanitizers is `bash scripts/sanitize.sh`
# (too long for CI on 2 cores; docs/reliability.md, "Sanitizers").
SPH_FUZZ_SECONDS=${SPH_FUZZ_SECONDS:-30} bash scripts/sanitize.sh asan-units tsan-units fuzz
