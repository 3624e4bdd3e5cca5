#!/usr/bin/env bash
# Configures and builds molremesh in BUILD_DIR (default: build/ in the repository).
# usage: build.sh [CMAKE_OPTION...]   options (e.g. -DMOLREMESH_MESHLAB_API=both) are passed to cmake,
#                                     which then configures again even if BUILD_DIR is configured.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
build=${BUILD_DIR:-$repo/build}
generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S "$repo" -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release "$@"
elif [ $# -gt 0 ]; then
  cmake -S "$repo" -B "$build" "$@"
fi
cmake --build "$build" --parallel "$(nproc)"
