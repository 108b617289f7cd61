#!/usr/bin/env bash
# Installs what is missing, builds everything, and runs the whole test suite on lavapipe with
# the Vulkan validation layers on (any validation message fails a test).
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
# The build's translation daemon (started by the build) goes when this script ends.
root=$(pwd)
trap '[ -x "$root/build/bin/crossrt" ] && "$root/build/bin/crossrt" daemon stop --build-dir "$root/build" > /dev/null 2>&1; true' EXIT
cmake --build build
cd build
ctest --output-on-failure --no-tests=error -j2
