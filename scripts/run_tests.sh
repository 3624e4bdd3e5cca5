#!/usr/bin/env bash
# The whole test suite from a fresh clone: installs the Debian dependencies, builds, runs ctest.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
build=${BUILD_DIR:-$repo/build}
bash "$repo/scripts/install_deps.sh"
BUILD_DIR=$build bash "$repo/scripts/build.sh"
cd "$build"
ctest --output-on-failure --parallel "$(nproc)" --timeout 1500
