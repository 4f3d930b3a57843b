#!/usr/bin/env bash
# The lint check: clang-tidy (.clang-tidy: the naming rules and a focused set of bug and
# performance checks, warnings as errors) on every C++ source of src/, apps/ and python/, and through
# its HeaderFilterRegex on the headers of src/sph, apps/sph and python/ they include, with the compile
# commands of a configured build directory (default build/; scripts/build.sh makes it). Exits 1 on
# any finding.
#   bash scripts/check_tidy.sh [BUILD_DIR] [FILE...]      (no file: all of src/, apps/ and python/)
# JOBS (default: nproc) units at a time. CLANG_TIDY names the program (default clang-tidy-14).
set -uo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
shift || true
tidy=${CLANG_TIDY:-$(command -v clang-tidy-14 || command -v clang-tidy)} || {
  echo "check_tidy: clang-tidy not found; run scripts/setup.sh (package clang-tidy-14)" >&2
  exit 2
}
[ -f "$build/compile_commands.json" ] || {
  echo "check_tidy: no $build/compile_commands.json; configure first (bash scripts/build.sh)" >&2
  exit 2
}
if [ $# -gt 0 ]; then
  files=("$@")
else
  mapfile -t files < <(find src apps python -name '*.cpp' | sort)
fi
log=$(mktemp -d)
trap 'rm -rf "$log"' EXIT

# Self-check: the naming rules flag each name marked bad below and none of the good ones, or
# .clang-tidy does not say what the project's conventions say.
cat >"$log/names.cpp" <<'CPP'
namespace sph {
inline constexpr int kLanes = 16;                                   // good
constexpr int lanes_bad = 3;                                        // bad: a constant is kPascalCase
using json = int;                                                   // good (nlohmann's name)
using alias_bad = int;                                              // bad: a type alias is PascalCase
enum class Mode { BruteForce, lower_bad };                          // bad: enumerators are PascalCase
struct Front { double T = 0, fine_T = 0, worstBad = 0; };           // bad: worstBad
class Widget {
 public:
  int value() const { return count_ + Bad_; }                       // good
 private:
  int count_ = 0;                                                   // good
  int Bad_ = 0;                                                     // bad: snake_case with a trailing _
  int missing = 0;                                                  // bad: no trailing _
};
double area(double coarse_Z, double WidthBad) {                     // bad: WidthBad
  constexpr int W = 4;                                              // good (an equation's symbol)
  constexpr double kHalf = 0.5;                                     // good (a local kConstant)
  const double scaled = coarse_Z * W * kHalf + WidthBad;
  return scaled;
}
void FunctionBad() {}                                               // bad: functions are snake_case
int _reserved = 0;                                                  // bad: a leading underscore
}  // namespace sph
CPP
"$tidy" --config-file=.clang-tidy --quiet "$log/names.cpp" -- -std=c++20 >"$log/names.out" 2>&1
found=$(grep -o "invalid case style for [a-z ]* '[A-Za-z_]*'" "$log/names.out" | grep -o "'.*'" | tr -d "'" | LC_ALL=C sort | tr '\n' ' ')
if [ "$found" != "Bad_ FunctionBad WidthBad _reserved alias_bad lanes_bad lower_bad missing worstBad " ]; then
  cat "$log/names.out"
  echo "check_tidy: self-check failed: the naming rules flagged [${found}], expected the nine names marked bad"
  exit 1
fi
# The sources are checked in units (scripts/tidy_units.py): each directory's sources of one
# compile command as one generated file, so that the headers they share are parsed and walked
# once, not once per source. A unit that does not compile as one file (two sources define the
# same name in their anonymous namespaces, a macro is defined twice) has its sources checked
# one by one instead, and the lint says so: the findings are the same either way.
python3 scripts/tidy_units.py "$build" "$log" "${files[@]}" >"$log/units.txt" || exit 2
export tidy log
# The compile commands are GCC's: clang does not know some of its warning options.
run_tidy() {  # file, log
  "$tidy" -p "$log" --config-file=.clang-tidy --quiet --extra-arg=-Wno-unknown-warning-option "$1" >"$2" 2>&1
}
check_unit() {  # unit, then its sources
  local unit=$1 out
  shift
  out=$log/$(basename "$unit").log
  run_tidy "$unit" "$out" && return 0
  if grep -q '\[clang-diagnostic-' "$out"; then
    echo "check_tidy: $(grep -m1 '\[clang-diagnostic-' "$out" | sed 's/ \[clang-diagnostic-.*//')"
    echo "check_tidy: so the $# sources of $(basename "$unit" .cpp) are checked one by one"
    local s status=0
    for s in "$@"; do
      run_tidy "$s" "$out.$(basename "$s").log" || status=1
    done
    rm -f "$out"
    [ $status -eq 0 ] && return 0
  fi
  echo "$unit" >>"$log/failed"
}
export -f run_tidy check_unit
xargs -d '\n' -n1 -P "${JOBS:-$(nproc)}" bash -c 'IFS=$'"'\\t'"' read -ra unit <<<"$1"; check_unit "${unit[@]}"' _ <"$log/units.txt"
if [ -s "$log/failed" ]; then
  # Each finding once (a header's shows up in every file that includes it).
  cat "$log"/*.log | grep -E '^[^ ].*: (warning|error): ' | sort -u
  echo "check_tidy: findings in $(wc -l <"$log/failed") of $(wc -l <"$log/units.txt") units of ${#files[@]} sources (and the headers they include); see .clang-tidy"
  exit 1
fi
echo "check_tidy: ${#files[@]} sources of src/, apps/ and python/ (in $(wc -l <"$log/units.txt") units) and the headers they include pass .clang-tidy"
