#!/usr/bin/env bash
# Builds PyMeshLab 2023.12 (MeshLab's meshlab-common, the io_base plugin and the pmeshlab Python module)
# from the vendored reduced source tree into a cache folder outside the clone, once: a complete cache
# (stamp file matching the tarball) is left alone, so a fresh machine pays the build (about 3 min on
# 2 cores) and later runs and CI reuse it.
#
# usage: build_pymeshlab.sh [TARBALL]
#   TARBALL                 default: ../shared/vendor/pymeshlab-2023.12-src-min.tar.gz next to the clone
#   MOLREMESH_PYMESHLAB_DIR cache folder (default ${XDG_CACHE_HOME:-$HOME/.cache}/molremesh/pymeshlab-2023.12)
#   MOLREMESH_PYMESHLAB_JOBS parallel compile jobs (default 2)
# Needs the packages of `scripts/install_deps.sh --pymeshlab`.
#
# Result, inside the cache folder:
#   python/pymeshlab/        the relocatable package (PYTHONPATH=<cache>/python; /usr/bin/python3 + numpy)
#   python/pymeshlab/lib/    libmeshlab-common.so, plugins/libio_base.so
#   interpreter              the Python it is built for (PYTHON_EXECUTABLE, default /usr/bin/python3)
#   src/PyMeshLab/src/meshlab/src/{common,vcglib}   the MeshLab 2023.12 headers and vcglib a plugin uses
set -euo pipefail

repo_root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
tarball=${1:-$repo_root/../shared/vendor/pymeshlab-2023.12-src-min.tar.gz}
cache=${MOLREMESH_PYMESHLAB_DIR:-${XDG_CACHE_HOME:-$HOME/.cache}/molremesh/pymeshlab-2023.12}
jobs=${MOLREMESH_PYMESHLAB_JOBS:-2}
python=${PYTHON_EXECUTABLE:-/usr/bin/python3}

if [ ! -f "$tarball" ]; then
  echo "build_pymeshlab: source tarball '$tarball' not found" >&2
  exit 1
fi
tarball=$(cd "$(dirname "$tarball")" && pwd)/$(basename "$tarball")
stamp="$cache/.complete"
tar_id=$(sha256sum "$tarball" | cut -d' ' -f1)
if [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$tar_id" ]; then
  [ -f "$cache/interpreter" ] || command -v "$python" >"$cache/interpreter"
  echo "build_pymeshlab: cache complete at $cache"
  exit 0
fi

mkdir -p "$cache"
cache=$(cd "$cache" && pwd)
src="$cache/src"
build="$cache/build"
prefix="$cache/python/pymeshlab"

# A half-unpacked tree from an interrupted run is replaced; an interrupted build is resumed by ninja.
if [ ! -f "$src/.unpacked" ] || [ "$(cat "$src/.unpacked")" != "$tar_id" ]; then
  rm -rf "$src" "$build"
  mkdir -p "$src"
  tar -xzf "$tarball" -C "$src"
  echo "$tar_id" >"$src/.unpacked"
fi

start=$(date +%s)
cmake -S "$src/PyMeshLab" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DMESHLAB_ALLOW_OPTIONAL_EXTERNAL_LIBRARIES=OFF \
  -DPYTHON_EXECUTABLE="$python" -DCMAKE_INSTALL_PREFIX="$prefix"
cmake --build "$build" --target pmeshlab io_base -- -j"$jobs"
# Only what was built: the whole tree's install also wants meshlab-common-gui, which PyMeshLab does
# not use.
for dir in src/meshlab/src/common src/meshlab/src/meshlabplugins/io_base src/pymeshlab; do
  cmake --install "$build/$dir"
done

PYTHONPATH="$cache/python" "$python" -c 'import pymeshlab; pymeshlab.MeshSet()'
# The scripts of meshlabserver_scripts/pymeshlab/ run again under this interpreter when started by another.
command -v "$python" >"$cache/interpreter"
echo "$tar_id" >"$stamp"
echo "build_pymeshlab: built in $(($(date +%s) - start)) s; PYTHONPATH=$cache/python"
