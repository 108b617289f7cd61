#!/usr/bin/env bash
# The main job on a fresh Debian 12 machine: install what is missing, build, translate the
# examples, run them on the default Vulkan device (a GPU if there is one, else lavapipe), and
# write the bloom image and the particle statistics table.
set -euo pipefail
source "$(dirname "$0")/configure.sh"
cmake --build build --target particles bloom
mkdir -p out
./build/examples/particles/particles 1000000 10 | tee out/particles.txt
# An image path as the first argument blooms that image; without one the example renders its own.
if [ $# -gt 0 ]; then
  ./build/examples/bloom/bloom "$1" out/bloom.png | tee out/bloom.txt
else
  ./build/examples/bloom/bloom "" out/bloom.png | tee out/bloom.txt
fi
echo "wrote out/bloom.png, out/bloom.txt and out/particles.txt"
