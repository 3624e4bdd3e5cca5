#!/usr/bin/env bash
# AddressSanitizer + UndefinedBehaviorSanitizer build of the CLI and the unit tests (into build-asan/),
# then the unit tests and, when given, the hostile corpus through the sanitized CLI.
# usage: sanitizer_build.sh [--readers-only] [CORPUS_DIR]
#   --readers-only builds and runs only the mesh-reader tests (the whole unit suite takes long to build);
#   CORPUS_DIR (from scripts/make_hostile_inputs.py) is then run with scripts/run_hostile.sh.
# Any sanitizer report aborts the process (halt_on_error), so run_hostile.sh counts it as a finding.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
build=${ASAN_BUILD_DIR:-$repo/build-asan}
jobs=${JOBS:-1}
readers_only=0
corpus=""
for arg in "$@"; do
  case "$arg" in
  --readers-only) readers_only=1 ;;
  *) corpus=$arg ;;
  esac
done
flags="-O1 -g -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined"
# The MeshLab/vcglib sources of the release build when there is one (no second download).
meshlab_source=()
[ -z "${MESHLAB_SOURCE_DIR:-}" ] && [ -d "$repo/build/_deps/meshlab-source/meshlab" ] &&
  MESHLAB_SOURCE_DIR=$repo/build/_deps/meshlab-source/meshlab
[ -n "${MESHLAB_SOURCE_DIR:-}" ] && meshlab_source=(-DMESHLAB_SOURCE_DIR="$MESHLAB_SOURCE_DIR")
if [ ! -f "$build/build.ninja" ]; then
  cmake -S "$repo" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Debug "${meshlab_source[@]}" \
    -DCMAKE_CXX_FLAGS_DEBUG="$flags" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
    -DMOLREMESH_BUILD_PLUGIN=OFF -DMOLREMESH_BUILD_BENCHMARKS=OFF
fi
export ASAN_OPTIONS=${ASAN_OPTIONS:-halt_on_error=1:detect_leaks=1:abort_on_error=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}
if [ "$readers_only" = 1 ]; then
  cmake --build "$build" --target molremesh test_mesh_readers -- -j"$jobs"
  (cd "$build" && ctest -R 'MeshReaders|NumberTokens' --output-on-failure --timeout 900)
else
  cmake --build "$build" -- -j"$jobs"
  (cd "$build" && ctest -L unit --output-on-failure --timeout 1800)
fi
if [ -n "$corpus" ]; then
  bash "$repo/scripts/run_hostile.sh" "$build/cli/molremesh" "$corpus"
fi
