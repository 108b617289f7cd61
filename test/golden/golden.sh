#!/usr/bin/env bash
# Golden tests of the generated code: translates a handful of classes and compares the generated
# header, host source and shaders with the files checked in under expected/. `update` rewrites
# them, so every change to the output shows in review as a diff of expected/.
set -euo pipefail

usage() {
  cat <<USAGE
usage: golden.sh check|update CROSSRT SOURCE_ROOT [CASE...]
  check   translates each case and compares it with test/golden/expected/CASE/ (exit 1 on a difference)
  update  translates each case and rewrites test/golden/expected/CASE/
  CROSSRT is the crossrt client (it translates in-process, --no-daemon); SOURCE_ROOT the repository.
  With CASE names, only those cases; the list is in this script.
USAGE
}
if [[ $# -lt 3 || "$1" == "--help" || "$1" == "-h" ]]; then usage; [[ "${1:-}" == --help || "${1:-}" == -h ]]; exit $?; fi
mode=$1 crossrt=$2 root=$(cd "$3" && pwd); shift 3
[[ "$mode" == check || "$mode" == update ]] || { usage; exit 2; }

# name | class | backend | --source files | more translate options | include directory of the class
cases=(
  "particles_vulkan|Particles|vulkan|examples/particles/Particles.cpp||examples/particles"
  "particles_cpu|Particles|cpu|examples/particles/Particles.cpp||examples/particles"
  "bloom_vulkan|Bloom|vulkan|examples/bloom/Bloom.cpp||examples/bloom"
  "primary_rays_vulkan|PrimaryRays|vulkan|examples/primary_rays/PrimaryRays.cpp libs/litert/BVHScene.cpp|--compose ISceneObject=BVHScene|examples/primary_rays"
  "primary_rays_cpu|PrimaryRays|cpu|examples/primary_rays/PrimaryRays.cpp libs/litert/BVHScene.cpp|--compose ISceneObject=BVHScene|examples/primary_rays"
  "sphere_paths_vulkan|SpherePaths|vulkan|examples/sphere_paths/SpherePaths.cpp||examples/sphere_paths"
  "sphere_paths_ispc|SpherePaths|ispc|examples/sphere_paths/SpherePaths.cpp||examples/sphere_paths"
  "lbvh_vulkan|LBVH|vulkan|libs/litebvh/LBVH.cpp||libs/litebvh"
  "lbvh_cpu|LBVH|cpu|libs/litebvh/LBVH.cpp||libs/litebvh"
  "callable_shading_vulkan|CallableShading|vulkan|test/classes/CallableShading.cpp|--virtual-level 3|test/classes"
  "shape_tracer_vulkan|ShapeTracer|vulkan|test/classes/ShapeTracer.cpp|--compose IScene=ShapeScene --virtual-level 3|test/classes"
  "sdf_leaf_tracer_vulkan|SdfLeafTracer|vulkan|test/classes/SdfLeafTracer.cpp libs/litert/SdfLeafScene.cpp|--compose ISceneObject=SdfLeafScene --virtual-level 3|test/classes"
  "textured_materials_vulkan|TexturedMaterials|vulkan|test/classes/TexturedMaterials.cpp||test/classes"
  "staged_saxpy_vulkan|StagedSaxpy|vulkan|test/conformance/cases/staged_saxpy.cpp||test/conformance/cases"
  "local_totals_vulkan|LocalTotals|vulkan|test/conformance/cases/local_totals.cpp||test/conformance/cases"
  "sort_pairs_vulkan|SortPairs|vulkan|test/conformance/cases/sort_pairs.cpp||test/conformance/cases"
)

expected_dir="$root/test/golden/expected"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failed=0
for entry in "${cases[@]}"; do
  IFS='|' read -r name class backend sources options include <<<"$entry"
  if [[ $# -gt 0 ]] && ! printf '%s\n' "$@" | grep -qx "$name"; then continue; fi
  out="$work/$name"
  source_args=()
  for s in $sources; do source_args+=(--source "$root/$s"); done
  # shellcheck disable=SC2086  # options are words
  if ! (cd "$root" && "$crossrt" translate --no-daemon --class "$class" --backend "$backend" --out "$out" \
        "${source_args[@]}" $options --templates "$root/templates" -- -std=c++17 \
        -I"$root/$include" -I"$root/libs/litemath" -I"$root/libs/litert" -I"$root/libs/litebvh" -I"$root/libs/litesdf" \
        -I"$root/libs/liteimage" -I"$root/libs/liteimage/compat" >"$work/$name.log" 2>&1); then
    echo "golden: $name: translation failed:"; cat "$work/$name.log"; failed=1; continue
  fi
  # Kept: the header, host source and shaders. Not kept: the embedded SPIR-V (its source is the
  # shaders), the manifest and depfile (they hold this machine's paths).
  rm -f "$out"/*_shaders.cpp "$out"/.crossrt-manifest.json "$out"/*.d
  if [[ "$mode" == update ]]; then
    rm -rf "${expected_dir:?}/$name"; mkdir -p "$expected_dir"; cp -r "$out" "$expected_dir/$name"
    echo "golden: $name: updated ($(find "$out" -type f | wc -l) files)"
  elif ! diff -ru "$expected_dir/$name" "$out" >"$work/$name.diff"; then
    echo "golden: $name: the generated code differs from test/golden/expected/$name:"
    sed "s|$out|(generated)|g" "$work/$name.diff" | head -200
    failed=1
  else
    echo "golden: $name: same ($(find "$out" -type f | wc -l) files)"
  fi
done
if [[ $failed -ne 0 && "$mode" == check ]]; then
  echo "golden: if the change is intended, run: test/golden/golden.sh update <crossrt> <source root>"
fi
exit $failed
