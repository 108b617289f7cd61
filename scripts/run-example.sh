#!/usr/bin/env bash
# The main job on a fresh Debian 12 machine: install what is missing, build, translate the
# examples, run them on the default Vulkan device (a GPU if there is one, else lavapipe), and
# write the bloom image, the particle statistics table and the Cornell box, path traced.
set -euo pipefail
source "$(dirname "$0")/configure.sh"
cmake --build build --target particles bloom path_tracer cornell_box_scene
mkdir -p out
# Without a GPU (and no driver chosen), the programs run on lavapipe with ray tracing from .deps/.
device=cpu
if command -v vulkaninfo >/dev/null && vulkaninfo --summary 2>/dev/null | grep -Eq "PHYSICAL_DEVICE_TYPE_(DISCRETE|INTEGRATED)_GPU"; then
  device=vulkan
elif [ -z "${VK_ICD_FILENAMES:-}${VK_DRIVER_FILES:-}${CROSSRT_DEVICE:-}" ] && [ -f .deps/lavapipe-rt/env.sh ]; then
  source .deps/lavapipe-rt/env.sh
fi
./build/examples/particles/particles 1000000 10 | tee out/particles.txt
# An image path as the first argument blooms that image; without one the example renders its own.
if [ $# -gt 0 ]; then
  ./build/examples/bloom/bloom "$1" out/bloom.png | tee out/bloom.txt
else
  ./build/examples/bloom/bloom "" out/bloom.png | tee out/bloom.txt
fi
# The Cornell box (glTF, written by scripts/make-cornell-box.py), path traced with litept's PathTracer:
# PathTracer_Vulkan where the default Vulkan device is a GPU, else PathTracer_CPU on all cores
# (lavapipe runs the same shaders some 50 times slower than the CPU class).
./build/examples/path_tracer/path_tracer build/data/scenes/cornell_box.gltf --device "$device" --size 256x256 --spp 256 \
  --out out/cornell_box.exr --out out/cornell_box.png | tee out/cornell_box.txt
echo "wrote out/bloom.png, out/bloom.txt, out/particles.txt and out/cornell_box.png (.exr: linear radiance)"
