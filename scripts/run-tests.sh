#!/usr/bin/env bash
# Installs what is missing, builds everything, and runs the whole test suite on lavapipe with
# the Vulkan validation layers on (any validation message fails a test).
set -euo pipefail
source "$(dirname "$0")/configure.sh"
# Real meshes for the mesh tests (cached; a mesh that cannot be fetched is skipped by its test).
"$(dirname "$0")/fetch-meshes.sh" >/dev/null || true
cmake --build build
cd build
ctest --output-on-failure --no-tests=error -j2
