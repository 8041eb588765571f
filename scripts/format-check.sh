#!/usr/bin/env bash
# Checks that every C and C++ file of the repository is formatted by .clang-format (exit 1 and the
# files that are not). scripts/test.sh (CI) runs it. With file arguments, checks
# only those.
set -euo pipefail
cd "$(dirname "$0")/.."
command -v clang-format > /dev/null || { echo "format-check: clang-format is not installed" >&2; exit 2; }
if [ $# -gt 0 ]; then files=("$@"); else mapfile -t files < <(git ls-files '*.cpp' '*.hpp' '*.c' '*.h'); fi
bad=()
for f in "${files[@]}"; do
  clang-format --dry-run -Werror "$f" > /dev/null 2>&1 || bad+=("$f")
done
if [ "${#bad[@]}" -gt 0 ]; then
  printf 'not formatted (clang-format -i <file>): %s\n' "${bad[@]}" >&2
  echo "format-check: ${#bad[@]} of ${#files[@]} files not formatted" >&2
  exit 1
fi
echo "format-check: ${#files[@]} files formatted"
