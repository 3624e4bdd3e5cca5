#!/usr/bin/env bash
# Fails when a tracked C++ file (*.h, *.cpp) differs from what the committed .clang-format makes of it,
# listing the files that drift. Needs clang-format 14 (scripts/install_deps.sh installs it).
# usage: check_format.sh        fix with: clang-format -i <file>...
set -euo pipefail
cd "$(dirname "$0")/.."
command -v clang-format >/dev/null || { echo "check_format: clang-format not found" >&2; exit 1; }
mapfile -t files < <(git ls-files -- '*.h' '*.cpp')
drift=()
for f in "${files[@]}"; do
  clang-format --style=file --dry-run --Werror "$f" >/dev/null 2>&1 || drift+=("$f")
done
if [ ${#drift[@]} -ne 0 ]; then
  echo "check_format: ${#drift[@]} of ${#files[@]} files differ from .clang-format (clang-format -i them):" >&2
  printf '  %s\n' "${drift[@]}" >&2
  exit 1
fi
echo "check_format: all ${#files[@]} C++ files formatted"
