#!/usr/bin/env bash
# Packs the device tests and what they need to run on another x86-64 Linux machine that has a
# Vulkan driver but none of this project's build: the test executable, the shared libraries it
# loads (glibc's excepted), the Vulkan loader, the Khronos validation layer and glslangValidator.
# The result is one compressed archive plus scripts/device-tests.sh, which unpacks and runs it.
#
#   scripts/device-bundle.sh [--benchmarks] [BUILD_DIR] [OUT_DIR]  (defaults: build, .device-bundle)
#
# --benchmarks adds the bench_* programs and the meshes they read.
# Then, on the GPU machine, in a copy of this repository holding OUT_DIR:
#   scripts/device-tests.sh OUT_DIR [CATCH_ARGS...]
#   scripts/device-tests.sh --benchmark OUT_DIR bench_lbvh [ARGS...]
set -euo pipefail

if [[ "${1:-}" == "--help" || "${1:-}" == "-h" ]]; then
  sed -n '2,12p' "$0" | sed 's/^# \{0,1\}//'
  exit 0
fi
benchmarks=0
if [[ "${1:-}" == "--benchmarks" ]]; then benchmarks=1; shift; fi
build=${1:-build}
out=${2:-.device-bundle}

tests="$build/test/crossrt_device_tests"
benches=(bench_examples bench_lbvh bench_sdf bench_textures bench_scan bench_radiance_fields)
echo "device-bundle: building crossrt_device_tests in $build"
cmake --build "$build" --target crossrt_device_tests >/dev/null
(( benchmarks )) && cmake --build "$build" --target "${benches[@]}" >/dev/null

stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
mkdir -p "$stage/bin" "$stage/lib" "$stage/layers"

glslang=$(grep -m1 '^Vulkan_GLSLANG_VALIDATOR_EXECUTABLE' "$build/CMakeCache.txt" | cut -d= -f2)
cp "$tests" "$stage/bin/"
cp "$glslang" "$stage/bin/glslangValidator"
echo "$glslang" > "$stage/glslang-path"  # the tests run it by the path they were built with

# Every shared library the programs load, except the C library's own, which the target has.
copy_deps() {
  ldd "$1" | awk '$3 ~ /^\// {print $3}' |
    grep -v -E '/(libc|libm|libdl|libpthread|librt|libresolv)\.so|ld-linux' |
    while read -r lib; do cp -L -n "$lib" "$stage/lib/"; done
}
copy_deps "$stage/bin/crossrt_device_tests"
copy_deps "$stage/bin/glslangValidator"
if (( benchmarks )); then
  for b in "${benches[@]}"; do cp "$build/bench/$b" "$stage/bin/"; copy_deps "$stage/bin/$b"; done
  mkdir -p "$stage/data" && cp -r "$build/data/meshes" "$stage/data/"
fi
# NVIDIA's Vulkan driver is libGLX_nvidia, which loads GLVND's dispatch libraries: bare images lack them.
for lib in libGLdispatch.so.0 libGLX.so.0 libEGL.so.1; do
  path=$(ldconfig -p | awk -v l="$lib" '$1 == l {print $NF; exit}')
  [[ -n "$path" ]] && cp -L -n "$path" "$stage/lib/"
done

# The validation layer and its manifest: the tests run with CROSSRT_VALIDATION=1 there too.
layer_json=/usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json
if [[ -f "$layer_json" ]]; then
  lib=$(sed -n 's/.*"library_path": *"\([^"]*\)".*/\1/p' "$layer_json")
  [[ "$lib" == /* ]] || lib=$(ldconfig -p | awk -v l="$lib" '$1 == l {print $NF; exit}')
  cp -L "$lib" "$stage/lib/"
  sed "s|\"library_path\": *\"[^\"]*\"|\"library_path\": \"../lib/$(basename "$lib")\"|" "$layer_json" > "$stage/layers/$(basename "$layer_json")"
else
  echo "device-bundle: note: no validation layer here ($layer_json); the device tests will run without it" >&2
fi

mkdir -p "$out"
tar -C "$stage" -cJf "$out/device-tests.tar.xz" .
echo "device-bundle: $(du -h "$out/device-tests.tar.xz" | cut -f1) in $out/device-tests.tar.xz ($(ls "$stage/lib" | wc -l) libraries)"
