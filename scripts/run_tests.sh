#!/usr/bin/env bash
# The whole test suite from a fresh clone: installs the Debian dependencies, builds, runs ctest, and says
# how many tests were skipped and why (without ../shared/data the tests on the shared meshes skip).
# usage: run_tests.sh [--pymeshlab]
#   The PyMeshLab 2023.12 plugin and its tests (label pymeshlab) are included when the PyMeshLab cache of
#   scripts/build_pymeshlab.sh is complete; --pymeshlab builds that cache first when it is not (once,
#   15-40 min on 2 cores).
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
build=${BUILD_DIR:-$repo/build}
pymeshlab=auto
for option in "$@"; do
  case "$option" in
  --pymeshlab) pymeshlab=on ;;
  *) echo "run_tests: unknown option '$option' (use --pymeshlab)" >&2; exit 1 ;;
  esac
done
pymeshlab_cache=${MOLREMESH_PYMESHLAB_DIR:-${XDG_CACHE_HOME:-$HOME/.cache}/molremesh/pymeshlab-2023.12}
cmake_options=()
if [ "$pymeshlab" = on ]; then
  bash "$repo/scripts/install_deps.sh" --pymeshlab
  MOLREMESH_PYMESHLAB_DIR=$pymeshlab_cache bash "$repo/scripts/build_pymeshlab.sh"
else
  bash "$repo/scripts/install_deps.sh"
fi
if [ -f "$pymeshlab_cache/.complete" ]; then
  cmake_options=(-DMOLREMESH_MESHLAB_API=both "-DMOLREMESH_PYMESHLAB_DIR=$pymeshlab_cache")
fi
BUILD_DIR=$build bash "$repo/scripts/build.sh" "${cmake_options[@]}"
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
