#!/usr/bin/env bash
# The install check (scripts/test.sh runs it after the tests): installs the already-built build/
# with `cmake --install` into a fresh prefix, moves the prefix elsewhere, and from a directory
# outside the repository
#   1. runs the installed `sph validate --quick` and `sph bench --suite tank --size small`, with
#      their default scenes, and checks that they read them from the moved prefix's
#      share/sph/scenes (validate prints "scenes from DIR"; bench.json records the tank scene);
#   2. imports the installed Python module sph (when built) and steps an installed scene;
#   3. configures and builds tests/install, a user's project of find_package(sph) linking
#      sph::solver, against the moved prefix, and runs it.
# What this proves: the install holds the program, its data, the libraries, their headers and a
# working package; the installed program finds its data from its own location (no path of the
# build or source tree is needed: the prefix is moved after installing, the build tree's
# sph-data-dir.txt is not installed, SPH_DATA_DIR is unset); the package's dependencies (fmt,
# nlohmann_json, OpenMP, PNG) are found by find_dependency. About 1.5 minutes on 2 cores.
#   bash scripts/check_install.sh [BUILD_DIR]         (default build/; build it first)
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
build=${1:-build}
[ -x "$build/sph" ] || { echo "check_install: $build/sph not found; build first (bash scripts/build.sh)" >&2; exit 2; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "check_install: FAILED: $*" >&2; exit 1; }
unset SPH_DATA_DIR
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive}
t0=$SECONDS

cmake --install "$build" --prefix "$tmp/installed" >"$tmp/install.log" || { cat "$tmp/install.log"; fail "cmake --install"; }
mv "$tmp/installed" "$tmp/prefix"
prefix=$tmp/prefix
for f in bin/sph include/sph/core/version.h include/sph/solver/simulation.h lib/cmake/sph/sphConfig.cmake \
  lib/cmake/sph/sphConfigVersion.cmake lib/cmake/sph/sphTargets.cmake share/sph/scenes/paper/tank_fill_3d.json \
  share/sph/scenes/validation/martin_moyce_2d.json share/sph/scenes/validation/martin_moyce_2d_particles.json; do
  [ -f "$prefix/$f" ] || fail "the install has no $f"
done
layers=$(sed -n 's/^ *set( *SPH_LAYERS \(.*\))/\1/p' CMakeLists.txt)
for l in $layers; do
  [ -f "$prefix/lib/libsph_$l.a" ] || [ -f "$prefix/lib/libsph_$l.so" ] || fail "the install has no library of layer $l"
  [ -d "$prefix/include/sph/$l" ] || fail "the install has no headers of layer $l"
done
[ ! -e "$prefix/bin/sph-data-dir.txt" ] || fail "the build tree's sph-data-dir.txt was installed"

mkdir "$tmp/work"
cd "$tmp/work"
"$prefix/bin/sph" validate --quick --no-progress -o validate >validate.log 2>&1 || { cat validate.log; fail "sph validate --quick"; }
grep -qx "sph: scenes from $prefix/share/sph/scenes/validation" validate.log ||
  { cat validate.log; fail "sph validate did not read the installed scenes ($prefix/share/sph/scenes/validation)"; }
"$prefix/bin/sph" bench --suite tank --size small --no-progress -o bench >bench.log 2>&1 || { cat bench.log; fail "sph bench --suite tank --size small"; }
scene=$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["tank"]["scene"])' bench/bench.json) ||
  fail "bench/bench.json has no tank.scene"
[ "$scene" = "$prefix/share/sph/scenes/paper/tank_fill_3d.json" ] ||
  fail "sph bench read the tank scene $scene, not the installed $prefix/share/sph/scenes/paper/tank_fill_3d.json"
ran=$SECONDS

# The Python module (when the build has it): installed with its stub, and `import sph` from the
# moved prefix runs a few steps of an installed scene.
case $build in /*) cache=$build/CMakeCache.txt ;; *) cache=$root/$build/CMakeCache.txt ;; esac
if grep -q '^SPH_PYTHON:BOOL=ON' "$cache"; then
  pydir=$(sed -n 's/^SPH_INSTALL_PYTHONDIR:STRING=//p' "$cache")
  python=$(sed -n 's/^SPH_PYTHON_EXECUTABLE:INTERNAL=//p' "$cache")
  ls "$prefix/$pydir"/sph.*.so >/dev/null 2>&1 || fail "the install has no Python module in $pydir"
  [ -f "$prefix/$pydir/sph.pyi" ] || fail "the install has no $pydir/sph.pyi"
  PYTHONPATH="$prefix/$pydir" "$python" - "$prefix" "$pydir" >python.log 2>&1 <<'PY' || { cat python.log; fail "import sph from the installed prefix"; }
import os, sys
import sph
prefix, pydir = sys.argv[1], sys.argv[2]
assert os.path.dirname(sph.__file__) == os.path.join(prefix, pydir), sph.__file__
scene = sph.load_scene(os.path.join(prefix, "share/sph/scenes/paper/dam_break_2d.json"),
                       overrides={"FluidBlocks[0].end": [0.1, 0.2]})
sim = sph.Simulation(scene, threads=1)
sim.step(3)
assert sim.steps == 3 and sim.positions.shape == (200, 2)
print("import sph:", sph.__file__)
PY
fi

cmake -S "$root/tests/install" -B consumer -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$prefix" \
  >consumer.log 2>&1 || { cat consumer.log; fail "configuring a find_package(sph) project"; }
cmake --build consumer >>consumer.log 2>&1 || { cat consumer.log; fail "building a project that links sph::solver"; }
./consumer/consumer || fail "the consumer program"
echo "check_install: passed in $((SECONDS - t0)) s: the install, moved with its prefix, ran validate --quick and" \
  "the small tank bench on its own share/sph/scenes from outside the repository ($((ran - t0)) s), imported sph, and a" \
  "find_package(sph) project linking sph::solver built and ran against it ($((SECONDS - ran)) s)"
