#!/bin/bash
# The path tracer against Blender's Cycles on four scenes: the Cornell box this project writes
# (area light, rough metal, glass), the same with a sphere and a rectangle light as well (opaque
# emitters in both renderers: cycles-reference.py makes them emitting meshes for Cycles), and two
# assimp-testmodels glTF models (2CylinderEngine, 110k triangles; ClearCoatTest, textures and
# normal maps) lit by Blender's "forest" HDR map. Each scene is rendered by
# scripts/cycles-reference.py and by path_tracer (PathTracer_CPU) at the same size, depth and spp;
# the table gives the PSNR (8-bit sRGB) and relative MSE (linear) of ours against Cycles', and each
# renderer's time on this machine's cores.
#
# Also an artist's room (scripts/make-room.py: glTF's default materials, an emissive panel, rough
# gold), 192x192 at 1024 spp, rendered by Cycles three ways: with the material fix-ups that make
# Cycles render glTF's BRDF as CrossRT does ("matched"), and as Blender's importer leaves it
# ("imported": Principled BSDF v1, Burley's diffuse under an added specular layer; and
# "imported-burley": its diffuse alone). The rows "imported" measure what differs by design.
set -euo pipefail

usage() {
  cat <<'EOF'
usage: scripts/compare-cycles.sh [--build DIR] [--out DIR] [--quick] [--only NAMES]
  --build DIR  the build folder with examples/path_tracer/path_tracer and data/scenes/ (default: build)
  --out DIR    where the images, compare_cycles.csv and compare_cycles.md go (default: out/compare_cycles)
  --quick      a quarter of the samples (a smoke run; the PSNR then measures noise more than bias)
  --only NAMES the scenes to render, comma-separated (default: all): cornell_box,
               cornell_box_shape_lights, 2CylinderEngine, ClearCoatTest, room, room_lambert,
               room_imported, room_imported_burley
Needs blender (3.4), oiiotool, and the Debian packages assimp-testmodels and blender-data.
Goal (issue 25): at least 35 dB on the Cornell box, 30 dB on the others.
EOF
}

root=$(cd "$(dirname "$0")/.." && pwd)
build=$root/build
out=$root/out/compare_cycles
scale=1
only=
while [ $# -gt 0 ]; do
  case "$1" in
    --build) build=$(cd "$2" && pwd); shift 2 ;;
    --out) out=$2; shift 2 ;;
    --quick) scale=4; shift ;;
    --only) only=,$2,; shift 2 ;;
    -h|--help) usage; exit 0 ;;
    *) echo "compare-cycles: error: unknown argument '$1'" >&2; usage >&2; exit 2 ;;
  esac
done

die() { echo "compare-cycles: error: $*" >&2; exit 1; }
tracer=$build/examples/path_tracer/path_tracer
cornell=$build/data/scenes/cornell_box.gltf
models=/usr/share/assimp/models/glTF2
forest=/usr/share/blender/datafiles/studiolights/world/forest.exr
[ -x "$tracer" ] || die "no $tracer: build the project first (scripts/configure.sh, then ninja -C build)"
[ -f "$cornell" ] || die "no $cornell: build the project first"
command -v blender >/dev/null || die "blender is not installed (apt-get install blender)"
command -v oiiotool >/dev/null || die "oiiotool is not installed (apt-get install openimageio-tools)"
[ -d "$models" ] || die "no $models (apt-get install assimp-testmodels)"
[ -f "$forest" ] || die "no $forest (apt-get install blender-data)"
mkdir -p "$out"

# blender-data's maps are DWAB-compressed; ZIP for every reader.
env_map=$out/forest.exr
[ -f "$env_map" ] || oiiotool "$forest" --compression zip -o "$env_map"

csv=$out/compare_cycles.csv
md=$out/compare_cycles.md
echo "scene,size,spp,depth,cycles_materials,cycles_s,crossrt_s,psnr_db,relmse,mean_ratio_r,mean_ratio_g,mean_ratio_b,goal_db" > "$csv"
{
  echo "| scene | size | spp | Cycles materials | Cycles (s) | PathTracer_CPU (s) | PSNR (dB) | relMSE | mean ours / Cycles (r, g, b) | goal |"
  echo "|---|---|---|---|---|---|---|---|---|---|"
} > "$md"

# The mean of each channel of an EXR, "r g b".
channel_means() { oiiotool "$1" --printstats | awk '/Stats Avg/ { print $3, $4, $5 }'; }

# The Cornell box with a sphere and a rectangle light as well.
/usr/bin/python3 "$root/scripts/make-cornell-box.py" --shape-lights "$out/cornell_box_shape_lights.gltf"
/usr/bin/python3 "$root/scripts/make-room.py" "$out/room.gltf"
/usr/bin/python3 "$root/scripts/make-room.py" --lambert "$out/room_lambert.gltf"

# name, file, size, spp, environment (- for none), goal in dB (- for none: a difference by
# design), the materials Cycles renders (cycles-reference.py --materials)
scenes=(
  "cornell_box|$cornell|128x128|4096|-|35|matched"
  "cornell_box_shape_lights|$out/cornell_box_shape_lights.gltf|128x128|4096|-|35|matched"
  "2CylinderEngine|$models/2CylinderEngine-glTF-Binary/2CylinderEngine.glb|160x120|1024|$env_map|30|matched"
  "ClearCoatTest|$models/ClearCoat-glTF/ClearCoatTest.gltf|320x240|1024|$env_map|30|matched"
  "room|$out/room.gltf|192x192|1024|-|35|matched"
  "room_lambert|$out/room_lambert.gltf|192x192|1024|-|35|matched"
  "room_imported|$out/room.gltf|192x192|1024|-|-|imported"
  "room_imported_burley|$out/room_lambert.gltf|192x192|1024|-|-|imported-burley"
)
known=","
for s in "${scenes[@]}"; do known+="${s%%|*},"; done
for name in ${only//,/ }; do
  [[ "$known" == *",$name,"* ]] || die "--only: no scene named '$name' (the scenes: ${known:1:-1})"
done
for s in "${scenes[@]}"; do
  IFS='|' read -r name file size spp env goal materials <<<"$s"
  [ -z "$only" ] || [[ "$only" == *",$name,"* ]] || continue
  spp=$((spp / scale))
  env_args=()
  [ "$env" = "-" ] || env_args=(--env "$env")
  echo "compare-cycles: $name: Cycles, $size, $spp spp ..." >&2
  cycles_log=$(blender -b --factory-startup --python-exit-code 1 --python "$root/scripts/cycles-reference.py" -- \
    "$file" --out "$out/${name}_cycles.exr" --size "$size" --depth 8 --seed 1 --threads "$(nproc)" --spp "$spp" \
    --materials "$materials" "${env_args[@]}" 2>&1) || { echo "$cycles_log" >&2; die "Cycles failed on $name"; }
  cycles_s=$(grep -o 'cycles: .* spp, [0-9.]* s' <<<"$cycles_log" | sed 's/.* spp, \([0-9.]*\) s/\1/')
  echo "compare-cycles: $name: path_tracer ..." >&2
  ours_log=$("$tracer" "$file" --size "$size" --depth 8 --seed 1 --spp "$spp" --device cpu "${env_args[@]}" \
    --compare "$out/${name}_cycles.exr" --out "$out/${name}_crossrt.exr" --out "$out/${name}_crossrt.png" 2>&1 | tr '\r' '\n') ||
    { echo "$ours_log" >&2; die "path_tracer failed on $name"; }
  ours_s=$(grep -o 'cpu: [0-9.]* s' <<<"$ours_log" | awk '{print $2}')
  psnr=$(grep -o 'PSNR [0-9.]* dB' <<<"$ours_log" | awk '{print $2}')
  relmse=$(grep -o 'relMSE [0-9.e+-]*' <<<"$ours_log" | awk '{print $2}')
  oiiotool "$out/${name}_cycles.exr" --ch R,G,B --colorconvert linear sRGB -d uint8 -o "$out/${name}_cycles.png"
  ratios=$(paste <(channel_means "$out/${name}_crossrt.exr" | tr ' ' '\n') \
    <(channel_means "$out/${name}_cycles.exr" | tr ' ' '\n') | awk '{ printf "%.3f ", $1 / $2 }')
  read -r ratio_r ratio_g ratio_b <<<"$ratios"
  echo "$name,$size,$spp,8,$materials,$cycles_s,$ours_s,$psnr,$relmse,$ratio_r,$ratio_g,$ratio_b,$goal" >> "$csv"
  if [ "$goal" = "-" ]; then
    met="by design"
  else
    met=">= $goal dB: $(awk -v p="$psnr" -v g="$goal" 'BEGIN { print (p >= g) ? "met" : "missed" }')"
  fi
  echo "| $name | $size | $spp | $materials | $cycles_s | $ours_s | $psnr | $relmse | $ratio_r, $ratio_g, $ratio_b | $met |" >> "$md"
done
cat "$md"
echo "compare-cycles: wrote $md, $csv and the images in $out" >&2
