#!/usr/bin/env bash
# Installs what is missing, builds everything, and runs the whole test suite on lavapipe with
# the Vulkan validation layers on (any validation message fails a test).
set -euo pipefail
source "$(dirname "$0")/configure.sh"
cmake --build build
cd build
ctest --output-on-failure --no-tests=error -j2
