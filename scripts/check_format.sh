#!/usr/bin/env bash
# The format check: every C++ file of src/, apps/, tests/ and python/ is as clang-format (.clang-format)
# writes it. Changes nothing: lists each file that differs, with clang-format's first
# complaints, and exits 1 if there is any. To fix a file: clang-format -i FILE.
#   bash scripts/check_format.sh [FILE...]          (no argument: the whole tree)
# CLANG_FORMAT names the program (default clang-format-14, Debian 12's, else clang-format).
set -uo pipefail
cd "$(dirname "$0")/.."
cf=${CLANG_FORMAT:-$(command -v clang-format-14 || command -v clang-format)} || {
  echo "check_format: clang-format not found; run scripts/setup.sh (package clang-format-14)" >&2
  exit 2
}
if [ $# -gt 0 ]; then
  files=("$@")
else
  mapfile -t files < <(find src apps tests python -name '*.h' -o -name '*.cpp' | sort)
fi
bad=0
for f in "${files[@]}"; do
  if ! out=$("$cf" --dry-run -Werror "$f" 2>&1); then
    bad=$((bad + 1))
    echo "$f: not formatted ($(grep -c 'error:' <<<"$out") places), e.g.:"
    grep -m 3 -A 2 'error:' <<<"$out" | sed 's/^/    /'
  fi
done
if [ $bad -ne 0 ]; then
  echo "check_format: $bad of ${#files[@]} files differ from $("$cf" --version | grep -o 'version [0-9.]*')'s format (.clang-format); run clang-format -i on them"
  exit 1
fi
echo "check_format: ${#files[@]} files formatted as .clang-format says"
