#!/usr/bin/env bash
# Builds the libFuzzer targets of the mesh readers with clang-14 (ASan + UBSan, into build-fuzz/)
# and runs each for a bounded time, seeded with a hostile corpus when one is given.
# usage: run_fuzzers.sh [SECONDS_PER_READER (30)] [SEED_CORPUS_DIR]
# Exit status non-zero when a fuzzer finds a crash, a leak, a sanitizer report or a hang; the
# reproducer is left in build-fuzz/findings/.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
build=${FUZZ_BUILD_DIR:-$repo/build-fuzz}
seconds=${1:-30}
seeds=${2:-}
# The MeshLab/vcglib sources of the release build when there is one (no second download).
meshlab_source=()
[ -z "${MESHLAB_SOURCE_DIR:-}" ] && [ -d "$repo/build/_deps/meshlab-source/meshlab" ] &&
  MESHLAB_SOURCE_DIR=$repo/build/_deps/meshlab-source/meshlab
[ -n "${MESHLAB_SOURCE_DIR:-}" ] && meshlab_source=(-DMESHLAB_SOURCE_DIR="$MESHLAB_SOURCE_DIR")
if [ ! -f "$build/build.ninja" ]; then
  CC=clang-14 CXX=clang++-14 cmake -S "$repo" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release "${meshlab_source[@]}" \
    -DMOLREMESH_FUZZ=ON -DMOLREMESH_BUILD_PLUGIN=OFF -DMOLREMESH_BUILD_TESTS=OFF -DMOLREMESH_BUILD_BENCHMARKS=OFF
fi
cmake --build "$build" --target fuzz_ply fuzz_off fuzz_stl fuzz_obj fuzz_wrl -- -j"${JOBS:-1}"
mkdir -p "$build/findings"
status=0
for format in ply off stl obj wrl; do
  corpus="$build/corpus_$format"
  mkdir -p "$corpus"
  if [ -n "$seeds" ]; then
    find "$seeds" -maxdepth 1 -type f -name "*.$format" -size -64k -exec cp -n {} "$corpus/" \;
  fi
  echo "run_fuzzers: fuzz_$format for $seconds s ($(find "$corpus" -type f | wc -l) seed files)"
  if ! "$build/fuzz/fuzz_$format" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=65536 \
      -print_final_stats=1 -artifact_prefix="$build/findings/${format}_" "$corpus" 2>"$build/fuzz_$format.log"; then
    echo "run_fuzzers: fuzz_$format FOUND A PROBLEM (see $build/fuzz_$format.log and $build/findings/)"
    tail -n 30 "$build/fuzz_$format.log"
    status=1
  fi
  grep -E '^stat::number_of_executed_units|^stat::peak_rss_mb' "$build/fuzz_$format.log" | tr '\n' ' '
  echo
done
exit "$status"
