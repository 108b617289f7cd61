#!/usr/bin/env bash
# Runs the device tests packed by scripts/device-bundle.sh on the machine this runs on, with the
# Vulkan validation layer on, on its first Vulkan device (or the one CROSSRT_DEVICE names).
#
#   scripts/device-tests.sh BUNDLE_DIR [CATCH_ARGS...]
#   scripts/device-tests.sh --benchmark BUNDLE_DIR BENCH [ARGS...]
#
# Extra arguments go to Catch2 (a test name, a [tag], --reporter junit, ...). With --benchmark it
# runs one bench_* program of a bundle made with --benchmarks instead, from a folder where the
# meshes lie as build/data/meshes, as the benchmarks expect them.
set -euo pipefail

if [[ $# -lt 1 || "$1" == "--help" || "$1" == "-h" ]]; then
  sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//'
  [[ $# -lt 1 ]] && exit 2 || exit 0
fi
benchmark=0
if [[ "$1" == "--benchmark" ]]; then benchmark=1; shift; fi
bundle=$(cd "$1" && pwd)
shift
root=$(mktemp -d)
tar -C "$root" -xJf "$bundle/device-tests.tar.xz"

# The tests call glslangValidator by the absolute path they were built with.
glslang=$(cat "$root/glslang-path")
if [[ ! -x "$glslang" ]]; then
  mkdir -p "$(dirname "$glslang")" && cp "$root/bin/glslangValidator" "$glslang" ||
    echo "device-tests: note: cannot place glslangValidator at $glslang; tests that compile GLSL will fail" >&2
fi

export LD_LIBRARY_PATH="$root/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
export VK_LAYER_PATH="$root/layers"
export CROSSRT_VALIDATION=${CROSSRT_VALIDATION:-1}
export CROSSRT_VERBOSE=${CROSSRT_VERBOSE:-1}  # the device and the hardware paths it offers
# NVIDIA's driver manifest where containers mount it, if the loader would not find it itself.
nvidia_icd=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
if [[ -z "${VK_DRIVER_FILES:-}" && -f "$nvidia_icd" ]]; then
  export VK_DRIVER_FILES=$nvidia_icd
fi
if (( benchmark )); then
  program=$1
  shift
  mkdir -p "$root/run/build/data" "$root/run/out"
  ln -sfn "$root/data/meshes" "$root/run/build/data/meshes"
  cd "$root/run"
  exec "$root/bin/$program" "$@"
fi
exec "$root/bin/crossrt_device_tests" "$@"
