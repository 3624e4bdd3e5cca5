#!/usr/bin/env bash
# The whole test suite from a fresh clone: installs the Debian dependencies, builds, runs ctest, and says
# how many tests were skipped and why (without ../shared/data the tests on the shared meshes skip).
# usage: run_tests.sh [--no-pymeshlab]
#   The PyMeshLab 2023.12 plugin and its tests (label pymeshlab) are part of the suite: the PyMeshLab
#   cache of scripts/build_pymeshlab.sh is built first when it is not complete (once per machine, about
#   3 min on 2 cores), from the vendored source next to the clone (../shared/vendor; without it they
#   are left out, saying so). --no-pymeshlab leaves the cache alone: the pymeshlab tests then run only
#   if it is complete already.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
build=${BUILD_DIR:-$repo/build}
pymeshlab=on
for option in "$@"; do
  case "$option" in
  --no-pymeshlab) pymeshlab=auto ;;
  --pymeshlab) pymeshlab=on ;; # the default; kept for scripts that pass it
  *) echo "run_tests: unknown option '$option' (use --no-pymeshlab)" >&2; exit 1 ;;
  esac
done
pymeshlab_cache=${MOLREMESH_PYMESHLAB_DIR:-${XDG_CACHE_HOME:-$HOME/.cache}/molremesh/pymeshlab-2023.12}
pymeshlab_source=$repo/../shared/vendor/pymeshlab-2023.12-src-min.tar.gz
if [ "$pymeshlab" = on ] && [ ! -f "$pymeshlab_source" ]; then
  [ -f "$pymeshlab_cache/.complete" ] ||
    echo "run_tests: the PyMeshLab tests are left out: its vendored source ../shared/vendor is missing"
  pymeshlab=auto
fi
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
