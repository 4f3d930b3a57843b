#!/usr/bin/env bash
# Runs the tests under sanitizers and fuzzes the scene reader, each in its own build directory
# (the normal build/ is not touched), with clang and Debian's compiler-rt and libomp:
#   asan        build-asan: every ctest test (gtest programs, the sph binary they run, the Python
#               readback tests; not the browser test and the repeats of the small benchmark) under
#               AddressSanitizer + UndefinedBehaviorSanitizer, leak detection on, any undefined
#               behaviour fatal. Built portable (-DSPH_NATIVE=OFF): the scalar code paths (no
#               AVX-512), so that both are tested (build/ is native).
#   asan-units  build-asan as above, but only the test programs of the layers whose tests never
#               run the sph binary (core, neighbors, solver, scene: tests/CMakeLists.txt's
#               SPH_SELF_CONTAINED_TEST_LAYERS), which build without the rest, less the long
#               physics runs (Hydrostatic, Conservation, Settling: thousands of steps through the
#               code paths the short solver tests take, 20 times slower under the sanitizer). CI
#               runs this one.
#   tsan        build-tsan: the tests of the parallel code (core, neighbors, solver: determinism
#               tests included), bench.smoke, and sph render (parallel frames, the ffmpeg feeder
#               thread) and view on a short run under ThreadSanitizer, OpenMP made visible to it
#               by LLVM's Archer tool; first a self-check that a race planted in a parallel_for
#               body is reported and a race-free one is not.
#   tsan-units  build-tsan: the self-check and the core, neighbors and solver tests (every
#               parallel loop of the neighbor search and the solver; the determinism tests at 1 to
#               4 threads), less the long physics runs, without building the sph binary. CI runs
#               this one.
#   fuzz        build-asan: the libFuzzer target of the scene reader (tests/fuzz; its corpus and
#               logs in build-fuzz/) under ASan +
#               UBSan: the saved crashers are replayed, then it fuzzes for SPH_FUZZ_SECONDS
#               (default 60).
# Usage: bash scripts/sanitize.sh [STAGE...]     (no argument: asan tsan fuzz, the whole set)
# scripts/test.sh (CI) runs asan-units tsan-units fuzz, to keep CI short on 2 cores; run the
# whole set before a release or after changing threaded, I/O or app code.
# Prints a summary; exits non-zero if any stage failed. JOBS (default: nproc) sets the build and
# ctest parallelism. Run scripts/setup.sh first (scripts/test.sh does).
set -uo pipefail
cd "$(dirname "$0")/.."
root=$PWD

jobs=${JOBS:-$(nproc)}
fuzz_seconds=${SPH_FUZZ_SECONDS:-60}
cxx=$(command -v "${SPH_SANITIZE_CXX:-clang++-14}") || {
  echo "sanitize: ${SPH_SANITIZE_CXX:-clang++-14} not found; run scripts/setup.sh (packages clang-14, libclang-rt-14-dev, llvm-14)" >&2
  exit 1
}
stages=("$@")
[ ${#stages[@]} -eq 0 ] && stages=(asan tsan fuzz)
for s in "${stages[@]}"; do
  case $s in asan | asan-units | tsan | tsan-units | fuzz) ;;
    *) echo "sanitize: unknown stage '$s' (expected asan, asan-units, tsan, tsan-units or fuzz)" >&2; exit 2 ;;
  esac
done

llvm_dir=$(dirname "$(dirname "$(readlink -f "$cxx")")")  # /usr/lib/llvm-14
symbolizer=$llvm_dir/bin/llvm-symbolizer
archer=$llvm_dir/lib/libarcher.so

# Tests run two at a time and each may use every core: idle OpenMP threads must sleep.
export OMP_WAIT_POLICY=passive
export ASAN_OPTIONS="detect_leaks=1:check_initialization_order=1:strict_init_order=1:detect_stack_use_after_return=1:strict_string_checks=1:external_symbolizer_path=$symbolizer"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:external_symbolizer_path=$symbolizer"

results=()
failed=0
record() {  # stage status seconds [note]
  results+=("$(printf '%-6s %-5s %5ss  %s' "$1" "$2" "$3" "${4:-}")")
  [ "$2" = ok ] || failed=1
}

configure_and_build() {  # dir, then cmake cache settings, then -- and the targets (none: all)
  local dir=$1; shift
  local defs=() targets=()
  while [ $# -gt 0 ] && [ "$1" != -- ]; do defs+=("$1"); shift; done
  [ $# -gt 0 ] && shift
  targets=("$@")
  # A cache made with another compiler would be wiped by CMake on configure, and the -D settings
  # of this call with it: start that directory's configuration afresh instead.
  if [ -f "$dir/CMakeCache.txt" ] && ! grep -q "^CMAKE_CXX_COMPILER:[A-Z]*=$cxx\$" "$dir/CMakeCache.txt"; then
    rm -rf "$dir/CMakeCache.txt" "$dir/CMakeFiles"
  fi
  # No Python module: an instrumented module cannot load into the uninstrumented python3 (the
  # sanitizer runtimes must come first), so its tests run in the plain build only.
  # -O1, as the sanitizers' documentation advises: instrumented code at -O3 takes twice as long
  # to build for little gain in the tests' run time.
  cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=Release "-DCMAKE_CXX_FLAGS_RELEASE=-O1 -DNDEBUG" \
    -DCMAKE_CXX_COMPILER="$cxx" -DSPH_PYTHON=OFF "${defs[@]}" >/dev/null || return 1
  local d
  for d in "${defs[@]}"; do
    local name=${d#-D}
    name=${name%%=*}
    if ! grep -qx "$name:[A-Z]*=${d#*=}" "$dir/CMakeCache.txt"; then
      echo "sanitize: $dir is not configured with ${d#-D}" >&2
      return 1
    fi
  done
  if [ ${#targets[@]} -gt 0 ]; then
    cmake --build "$dir" -j "$jobs" --target "${targets[@]}"
  else
    cmake --build "$dir" -j "$jobs"
  fi
}

# Every ctest test of a build directory. The SmallSuites tests share one run of the benchmark's
# small suite (SetUpTestSuite) that ctest would repeat in each test's own process, seven times
# over: under a sanitizer they run here as one gtest process instead, the same checks.
# Left out as well, to keep CI short: bench.smoke and BenchCli.SmallNeighborsRunWritesItsFiles
# (the same small benchmark code as SmallSuites, run a third and fourth time) and the browser test
# (its subject is the page's JavaScript; the page builder runs under the sanitizers in
# test_render's Viewer tests).
run_suite() {  # dir
  local dir=$1 status=0
  ctest --test-dir "$dir" --output-on-failure --no-tests=error -j "$jobs" \
    -E '^(SmallSuites\.|bench\.smoke$|BenchCli\.SmallNeighborsRunWritesItsFiles$|py\.view_browser_test$)' || status=1
  local log=$dir/small_suites.log
  if ! (cd "$dir/tests" && ./test_bench --gtest_filter='SmallSuites.*') >"$log" 2>&1 ||
    ! grep -q '^\[  PASSED  \] [1-9]' "$log"; then
    cat "$log"; echo "sanitize: SmallSuites.* failed in $dir (log: $log)"; status=1
  else
    echo "SmallSuites.* (one process): $(grep '^\[  PASSED  \]' "$log")"
  fi
  return $status
}

stage_asan() {
  local t0=$SECONDS status=ok
  echo "== sanitize asan: build-asan (AddressSanitizer + UndefinedBehaviorSanitizer, portable: scalar paths), whole ctest suite"
  if ! configure_and_build build-asan -DSPH_SANITIZE=address,undefined -DSPH_NATIVE=OFF -DSPH_FUZZ=ON; then
    record asan FAIL $((SECONDS - t0)) "build failed"; return
  fi
  local built=$SECONDS
  run_suite build-asan || status=FAIL
  record asan $status $((SECONDS - t0)) "build $((built - t0))s, tests $((SECONDS - built))s"
}

# The test programs of the self-contained layers only (they build without the sph binary).
unit_layers=(core neighbors solver scene)
unit_targets=("${unit_layers[@]/#/test_}")
unit_label="^($(IFS='|'; echo "${unit_layers[*]}"))\$"
long_physics='^(Hydrostatic|Conservation|Settling|BoundarySettling)\.'
# Under ASan also the determinism tests over 1 to 4 threads: every mode's steps again at each thread
# count (about 110 s of ASan time), through the paths the other solver tests take; they are what
# TSan is for, and TSan runs them.
asan_skip="$long_physics|^Determinism\.EveryModeIsBitwiseIdentical"


stage_asan-units() {
  local t0=$SECONDS status=ok
  echo "== sanitize asan-units: build-asan (AddressSanitizer + UndefinedBehaviorSanitizer, portable), the ${unit_layers[*]} tests"
  if ! configure_and_build build-asan -DSPH_SANITIZE=address,undefined -DSPH_NATIVE=OFF -DSPH_FUZZ=ON -- "${unit_targets[@]}"; then
    record asan-u FAIL $((SECONDS - t0)) "build failed"; return
  fi
  local built=$SECONDS
  ctest --test-dir build-asan --output-on-failure --no-tests=error -j "$jobs" -L "$unit_label" -E "$asan_skip" ||
    status=FAIL
  record asan-u $status $((SECONDS - t0)) "build $((built - t0))s, tests $((SECONDS - built))s"
}

# A parallel_for whose body writes one shared variable from every thread (argument "race"), or
# only its own element: TSan must report the first and nothing in the second, or the OpenMP setup
# below (Archer, the libomp suppression) hides real races or reports false ones.
tsan_self_check() {
  local dir=build-tsan/self-check
  mkdir -p "$dir"
  cat >"$dir/race.cpp" <<'EOF'
#include <cstdio>
#include <cstring>
#include <vector>
#include <sph/core/parallel.h>
int main(int argc, char** argv) {
  const bool race = argc > 1 && std::strcmp(argv[1], "race") == 0;
  sph::set_num_threads(2);
  std::vector<double> v(1 << 16, 1.0);
  double shared = 0;
  for (int rep = 0; rep < 20; ++rep) {
    sph::parallel_for(v.size(), [&](std::size_t i) {
      v[i] += static_cast<double>(rep);
      if (race && i % 4096 == 0) shared += v[i];
    });
    double sum = 0;
    for (double x : v) sum += x;  // the main thread reads what every thread wrote
    v[rep] = sum * 1e-9;
  }
  std::printf("%g %g\n", v[0], shared);
}
EOF
  "$cxx" -std=c++20 -O1 -gline-tables-only -fsanitize=thread -fopenmp -Isrc "$dir/race.cpp" build-tsan/libsph_core.a \
    -o "$dir/race" -Wl,-rpath,"$llvm_dir/lib" || return 1
  local out
  out=$(ARCHER_OPTIONS=verbose=1 "$dir/race" 2>&1)
  if [ $? -ne 0 ] || grep -q "WARNING: ThreadSanitizer" <<<"$out"; then
    echo "$out"; echo "tsan self-check: a race-free parallel_for was reported"; return 1
  fi
  if ! grep -q "Archer detected OpenMP application with TSan" <<<"$out"; then
    echo "$out"; echo "tsan self-check: Archer ($archer) did not start"; return 1
  fi
  out=$("$dir/race" race 2>&1)
  if [ $? -eq 0 ] || ! grep -q "WARNING: ThreadSanitizer: data race" <<<"$out"; then
    echo "$out"; echo "tsan self-check: the race planted in a parallel_for body was not reported"; return 1
  fi
  echo "tsan self-check: Archer active; a planted race is reported, the race-free loop is clean"
}

# A short run, rendered to PNGs and an MP4 on 2 threads, and its page, all under TSan.
tsan_render_check() {
  local out=build-tsan/render_check
  rm -rf "$out"
  if ./build-tsan/sph run scenes/paper/dam_break_2d.json --steps 200 --every 25 --threads 2 --no-progress \
       -o "$out" >"$out.log" 2>&1 &&
     ./build-tsan/sph render "$out" --mp4 --size 320x240 --threads 2 --no-progress >>"$out.log" 2>&1 &&
     ./build-tsan/sph view "$out" >>"$out.log" 2>&1 &&
     [ -s "$out/render/movie.mp4" ] && [ -s "$out/render/frame_000008.png" ] && [ -s "$out/view.html" ]; then
    echo "tsan render check: sph run, render --mp4 and view on 2 threads, no race"
  else
    cat "$out.log"; echo "tsan render check failed (log: $out.log)"; return 1
  fi
}

# tsan (whole: with the sph binary, bench.smoke and the render check) or tsan-units (argument
# "units": the self-check and the core, neighbors and solver tests only).
run_tsan() {
  local units=${1:-} name=tsan t0=$SECONDS status=ok targets=(sph test_core test_neighbors test_solver)
  [ -n "$units" ] && name=tsan-u targets=(test_core test_neighbors test_solver)
  echo "== sanitize $name: build-tsan (ThreadSanitizer + Archer), the core, neighbors and solver tests${units:+ only}"
  if ! configure_and_build build-tsan -DSPH_SANITIZE=thread -- "${targets[@]}"; then
    record $name FAIL $((SECONDS - t0)) "build failed"; return
  fi
  local built=$SECONDS
  # Archer (LLVM's OMPT tool) tells TSan where OpenMP synchronizes (fork, join, barriers, the
  # dynamic schedule's hand-outs). libomp itself is not instrumented: the calls it makes into
  # intercepted functions (its own memset, free, pthread mutexes) are suppressed; every access
  # our code makes, inside parallel loops or not, is checked.
  printf '# libomp internals only (see scripts/sanitize.sh)\ncalled_from_lib:libomp.so.5\n' >build-tsan/tsan.supp
  export OMP_TOOL_LIBRARIES=$archer
  export TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1:suppressions=$root/build-tsan/tsan.supp:external_symbolizer_path=$symbolizer"
  tsan_self_check || status=FAIL
  # Every piece of parallel code: the neighbor search, the solver (the determinism tests run 1 to
  # 4 threads) and, through bench.smoke (sph bench --threads 1,2), the benchmark's list checks.
  local skip=()
  [ -n "$units" ] && skip=(-E "$long_physics")
  ctest --test-dir build-tsan --output-on-failure --no-tests=error -j "$jobs" -L '^(core|neighbors|solver)$' "${skip[@]}" ||
    status=FAIL
  if [ -z "$units" ]; then
    ctest --test-dir build-tsan --output-on-failure --no-tests=error -R '^bench\.smoke$' || status=FAIL
    # The other threads: sph render draws frames in a parallel_for and feeds ffmpeg from a thread
    # of its own; sph compare and sph view read what the runs wrote.
    tsan_render_check || status=FAIL
  fi
  unset OMP_TOOL_LIBRARIES TSAN_OPTIONS
  record $name $status $((SECONDS - t0)) "build $((built - t0))s, self-check + tests $((SECONDS - built))s"
}
stage_tsan() { run_tsan; }
stage_tsan-units() { run_tsan units; }

stage_fuzz() {
  local t0=$SECONDS status=ok note
  echo "== sanitize fuzz: build-asan (libFuzzer + ASan + UBSan), scene reader for ${fuzz_seconds}s"
  # In build-asan (the same sanitizers and libraries as the asan stages, sph_scene with the
  # fuzzer's coverage as well): one build of the libraries for both.
  if ! configure_and_build build-asan -DSPH_SANITIZE=address,undefined -DSPH_NATIVE=OFF -DSPH_FUZZ=ON \
    -- scene_reader_fuzz; then
    record fuzz FAIL $((SECONDS - t0)) "build failed"; return
  fi
  local fuzzer=build-asan/tests/fuzz/scene_reader_fuzz
  mkdir -p build-fuzz
  # Inputs that once crashed the reader, each run whole (some are longer than -max_len below).
  if ! "$fuzzer" tests/fuzz/regressions/* >build-fuzz/regressions.log 2>&1; then
    cat build-fuzz/regressions.log
    record fuzz FAIL $((SECONDS - t0)) "a saved crasher in tests/fuzz/regressions fails again"; return
  fi
  # A fresh corpus every run, seeded with every scene of the repository; findings go to
  # build-fuzz/findings, never into the source tree.
  rm -rf build-fuzz/corpus build-fuzz/findings
  mkdir -p build-fuzz/corpus build-fuzz/findings
  # (each under its path, / as _: scenes/paper/block_3d.json and scenes/dfsph/block_3d.json
  # are both seeds, where one name each kept the first and cp warned of the others)
  for f in scenes/*/*.json tests/scene/bad/*.json tests/fuzz/seeds/*.json; do cp "$f" "build-fuzz/corpus/${f//\//_}"; done
  local seeds
  seeds=$(ls build-fuzz/corpus | wc -l)
  "$fuzzer" -max_total_time="$fuzz_seconds" -max_len=8192 -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
    -dict=tests/fuzz/scene.dict -artifact_prefix=build-fuzz/findings/ build-fuzz/corpus >build-fuzz/fuzz.log 2>&1
  local rc=$?
  local runs rate corpus
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' build-fuzz/fuzz.log | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' build-fuzz/fuzz.log | tail -1)
  corpus=$(grep -o 'corp: [0-9]*/[0-9A-Za-z]*' build-fuzz/fuzz.log | tail -1 | cut -c7-)
  note="${runs:-?} inputs, ${rate:-?}/s; corpus: $seeds seeds -> ${corpus:-?} inputs/bytes"
  if [ $rc -ne 0 ]; then
    status=FAIL
    grep -v -E '^(#[0-9]+|INFO:|	NEW_FUNC)' build-fuzz/fuzz.log | head -80
    note="FINDING (exit $rc): $(ls build-fuzz/findings | tr '\n' ' ')- reproduce with $fuzzer build-fuzz/findings/FILE; $note"
  else
    grep -E '^(#[0-9]+ *DONE|Done|stat::)' build-fuzz/fuzz.log
  fi
  record fuzz $status $((SECONDS - t0)) "$note"
}

for s in "${stages[@]}"; do
  "stage_$s"
done

echo
echo "== sanitize summary (stage, result, wall time)"
printf '%s\n' "${results[@]}"
if [ $failed -ne 0 ]; then
  echo "sanitize: FAILED"
  exit 1
fi
echo "sanitize: all passed"
