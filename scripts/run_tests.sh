#!/usr/bin/env bash
# The whole test suite from a fresh clone: installs the Debian dependencies, builds, runs ctest, and says
# how many tests were skipped and why (without ../shared/data the tests on the shared meshes skip).
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
build=${BUILD_DIR:-$repo/build}
bash "$repo/scripts/install_deps.sh"
BUILD_DIR=$build bash "$repo/scripts/build.sh"
cd "$build"
status=0
ctest --output-on-failure --parallel "$(nproc)" --timeout 1500 || status=$?
log=Testing/Temporary/LastTest.log
if [ -f "$log" ]; then
  # A skipped GoogleTest prints "<file>:<line>: Skipped" and then its reason.
  skipped=$(grep -c -E '^\[  SKIPPED \] [^ ]+ \(' "$log" || true)
  if [ "$skipped" -gt 0 ]; then
    echo "$skipped tests skipped:"
    grep -A1 -E ': Skipped$' "$log" | grep -v -E ': Skipped$|^--$' | sort | uniq -c | sed 's/^ */  /'
  else
    echo "0 tests skipped"
  fi
fi
exit "$status"
