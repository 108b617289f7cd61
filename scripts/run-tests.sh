#!/usr/bin/env bash
# Installs what is missing, builds everything, and runs the whole test suite on lavapipe with
# the Vulkan validation layers on (any validation message fails a test).
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build
cd build
ctest --output-on-failure --no-tests=error -j2
