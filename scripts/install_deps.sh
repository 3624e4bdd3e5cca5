#!/usr/bin/env bash
# Installs every Debian package molremesh needs to build, test and benchmark (Debian bookworm).
# Safe to run again: apt skips what is already there. Needs root (or sudo).
# usage: install_deps.sh [--benchmarks] [--pictures] [--unseen] [--pymeshlab]
#   --benchmarks adds CGAL, the benchmark-only baseline, and matplotlib for the scaling plot;
#   --unseen adds EDTSurf, PyMOL and scikit-image, the surface generators of benchmarks/unseen_inputs.py
#            and scripts/make_broken_surfaces.py;
#   --pictures adds ImageMagick and xdotool, for scripts/make_pictures.sh (README screenshots of the
#              MeshLab GUI);
#   --pymeshlab adds what scripts/build_pymeshlab.sh needs to build PyMeshLab 2023.12 from the vendored
#               sources (pybind11, Python headers, numpy, Qt SVG).
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config dpkg-dev ca-certificates
  meshlab
  qtbase5-dev libqt5opengl5-dev libqt5xmlpatterns5-dev libglew-dev
  libeigen3-dev libtbb-dev libcli11-dev nlohmann-json3-dev libopenvdb-dev libboost-dev
  freesasa libjson-c-dev libxml2-dev zlib1g-dev gemmi-dev tao-pegtl-dev
  snakemake
  libgtest-dev libbenchmark-dev
  xvfb xauth
  tetgen
  clang-format
  clang-14 libfuzzer-14-dev
)
for option in "$@"; do
  case "$option" in
  --benchmarks) packages+=(libcgal-dev libball1.5-dev python3-matplotlib) ;;
  --pictures) packages+=(imagemagick xdotool) ;;
  --unseen) packages+=(edtsurf python3-pymol python3-skimage) ;;
  --pymeshlab) packages+=(pybind11-dev python3-dev python3-numpy libqt5svg5-dev) ;;
  *) echo "install_deps: unknown option '$option' (use --benchmarks, --pictures, --unseen, --pymeshlab)" >&2; exit 1 ;;
  esac
done

sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install_deps: run as root or install sudo" >&2; exit 1; }
  sudo_cmd=(sudo)
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#packages[@]} packages present"
  exit 0
fi
echo "install_deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -q
"${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
