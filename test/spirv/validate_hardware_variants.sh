#!/bin/bash
# Compiles every shader variant generated for GPU hardware that lavapipe lacks under a build tree
# with glslangValidator, checks that it asks for that hardware, and validates the SPIR-V with
# spirv-val. Lavapipe cannot run these shaders, so this is what a machine without them can check.
#   *_RayQuery*.comp: ray queries (GL_EXT_ray_query), capability RayQueryKHR;
#   *_Textures.comp and *_Textures.rgen: arrays of textures indexed per thread (descriptor indexing),
#   capabilities RuntimeDescriptorArray and SampledImageArrayNonUniformIndexing;
#   *_Callables.rgen and *.rcall: a kernel as a ray generation shader and the callable shaders its
#   virtual calls execute (ray tracing pipelines, GL_EXT_ray_tracing), capability RayTracingKHR;
#   *_Intersections.rgen, *.rint, *.rchit and *.rmiss: a kernel whose composed traversal traces its
#   leaves, with their intersection, closest-hit and miss shaders, capability RayTracingKHR.
# Usage: validate_hardware_variants.sh <glslangValidator> <spirv-val> <spirv-dis> <build dir> <expected shader>...
# Each expected shader (a path ending, e.g. PrimaryRays_Vulkan/shaders/kernel1D_CastRays_RayQuery.comp)
# must be among those found, so a generator that stopped writing them fails here.
set -u
glslang=$1 spirvval=$2 spirvdis=$3 build=$4
shift 4
# The package tests build user projects under test/package-*, and the parallel-build test a whole
# tree under test/parallel-build, at the same time: not searched, their shaders may be half written
# or already removed.
mapfile -t shaders < <(find "$build" \( -path "$build/test/package-*" -o -path "$build/test/parallel-build" \) -prune -o \( -name '*_RayQuery.comp' -o -name '*_Textures.comp' \
                         -o -name '*.rgen' -o -name '*.rcall' -o -name '*.rint' -o -name '*.rchit' -o -name '*.rmiss' \) -path '*/shaders/*' -print | sort -u)
status=0
for expected in "$@"; do
  found=$(printf '%s\n' "${shaders[@]}" | grep -- "/$expected\$" | head -1)
  if [ -z "$found" ]; then
    echo "FAIL: no generated shader ends with $expected"
    status=1
    continue
  fi
  # Written by the class's last translation, not left from an earlier one (outputs are never
  # deleted): the class folder's manifest lists it.
  class_dir=${found%/shaders/*}
  if ! grep -q "\"shaders/${found##*/shaders/}\"" "$class_dir/.crossrt-manifest.json" 2> /dev/null; then
    echo "FAIL: $found is not among the outputs of its class's last translation ($class_dir/.crossrt-manifest.json)"
    status=1
  fi
done
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
checked=0
for shader in "${shaders[@]}"; do
  spv="$work/$(basename "$shader").spv"
  if ! "$glslang" -V --target-env vulkan1.2 -o "$spv" "$shader" > "$work/log" 2>&1; then
    echo "FAIL: $shader does not compile:"; cat "$work/log"; status=1; continue
  fi
  needed=()
  case "$shader" in *_RayQuery*) needed+=(RayQueryKHR) ;; esac
  case "$shader" in *_Textures.comp | *_Textures.rgen) needed+=(RuntimeDescriptorArray SampledImageArrayNonUniformIndexing) ;; esac
  case "$shader" in *.rgen | *.rcall | *.rint | *.rchit | *.rmiss) needed+=(RayTracingKHR) ;; esac
  "$spirvdis" "$spv" > "$work/dis" 2>/dev/null
  missing=""
  for capability in "${needed[@]}"; do
    grep -q "OpCapability $capability\$" "$work/dis" || missing+=" $capability"
  done
  if [ -n "$missing" ]; then
    echo "FAIL: $shader compiled without the capabilities$missing"; status=1; continue
  fi
  if ! "$spirvval" --target-env vulkan1.2 "$spv" > "$work/log" 2>&1; then
    echo "FAIL: spirv-val rejects $shader:"; cat "$work/log"; status=1; continue
  fi
  echo "valid: $shader (${needed[*]})"
  checked=$((checked + 1))
done
if [ "$status" -eq 0 ] && [ "$checked" -gt 0 ]; then
  echo "OK: $checked hardware variant shaders valid"
else
  echo "FAIL: $checked of ${#shaders[@]} hardware variant shaders valid"
  exit 1
fi
