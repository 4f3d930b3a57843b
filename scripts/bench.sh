#!/usr/bin/env bash
# Builds in Release and runs the benchmark suites at the sizes of the performance work:
#   1. neighbors (8k, 64k, 512k points) and steps (8k, 64k, 512k particles), 1 and 2 threads,
#      float and double                                              -> OUT/
#   2. the paper's Fig. 4 tank, every mode, 3 interleaved repeats     -> OUT/tank/
#   3. the 1M-particle dam break in float (the target of the issue)   -> OUT/steps_1m/
#   4. its peak memory per mode, one fresh process each               -> OUT/memory_1m_<mode>/
# About 4 minutes on the project's 2-core machine. Every directory gets bench.json (machine,
# build, all figures) and one CSV per suite; tables are printed as the runs go.
#   bash scripts/bench.sh [OUT_DIR] [extra sph bench options, e.g. --threads 2 --repeats 3]
# OpenMP threads sleep while they wait (OMP_WAIT_POLICY=passive) unless the environment says
# otherwise: on a shared machine spinning threads that lose their core make 2-thread timings
# up to ten times slower and meaningless. bench.json records the policy used.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/bench}
shift || true
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive}
bash scripts/build.sh
start=$SECONDS
./build/sph bench --size large --suite neighbors,steps -o "$out" "$@"
./build/sph bench --size large --suite tank --repeats 3 -o "$out/tank" "$@"
./build/sph bench --suite steps --particles 1000000 --precision float -o "$out/steps_1m" "$@"
# Peak memory per particle is clean only for the first workload of a process (later ones inherit
# the heap of earlier ones), so the 1M memory figure of each mode comes from a fresh process.
for m in standard adaptive verlet; do
  ./build/sph bench --suite steps --particles 1000000 --precision float --threads 2 --modes $m --step-runs 1 \
    -o "$out/memory_1m_$m" --no-progress "$@"
done
echo
echo "bench.sh: done in $((SECONDS - start)) s. Results:"
for d in "$out" "$out/tank" "$out/steps_1m" "$out"/memory_1m_*; do
  echo "  $d/bench.json  $(cd "$d" && ls -- *.csv | tr '\n' ' ')"
done
