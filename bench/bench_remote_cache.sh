#!/usr/bin/env bash
# Benchmark of the remote translation cache (a program that prints a table, not a test).
# The examples (particles, bloom, primary_rays, sphere_paths) as a project outside the CrossRT
# tree, built against an installed CrossRT in four build trees, each in a folder of its own and
# each from its own copy of the sources, sharing one redis-server on a loopback port:
#   A: empty remote cache; B: warm remote cache (A's translations);
#   C, D: the same two with ccache on the compiler (CCACHE_BASEDIR, empty ccache before C).
# Translation time is the sum of the translation steps' times in .ninja_log; build time is the wall
# time of `cmake --build`. Writes out/remote_cache.csv.
# Then the cost of signed entries (a team key, docs/remote-cache.md "Trust"): interleaved rounds of
# fetching each example class from a warm store, from a database of unsigned entries and one of
# signed entries (verified with HMAC-SHA256), as a ratio. Writes out/remote_cache_verify.csv.
#   bench/bench_remote_cache.sh [--verify-only] [BUILD_DIR (default build)]
set -euo pipefail
if [[ "${1:-}" == --help || "${1:-}" == -h ]]; then
  echo "usage: bench/bench_remote_cache.sh [--verify-only] [BUILD_DIR (default build)]"
  echo "  Clean builds of the examples with an empty and a warm remote translation cache (Redis),"
  echo "  with and without ccache; prints a table and writes out/remote_cache.csv. Then fetches"
  echo "  with and without verifying signatures (a team key); writes out/remote_cache_verify.csv."
  echo "  --verify-only: only the second part."
  exit 0
fi
verify_only=0
[[ "${1:-}" == --verify-only ]] && verify_only=1 && shift
root=$(cd "$(dirname "$0")/.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
for tool in redis-server redis-cli ccache ninja; do
  command -v "$tool" > /dev/null || { echo "bench_remote_cache: $tool is missing (scripts/install-deps.sh)"; exit 1; }
done
work=$(mktemp -d /tmp/crossrt-bench-remote.XXXXXX)
redis_pid=""
cleanup() {
  for t in "$work"/tree-*; do [ -d "$t/build" ] && "$work/prefix/bin/crossrt" daemon stop --build-dir "$t/build" > /dev/null 2>&1; done
  [ -n "$redis_pid" ] && kill "$redis_pid" 2> /dev/null
  rm -rf "$work"
}
trap cleanup EXIT
port=$((20000 + RANDOM % 20000))
redis-server --port "$port" --bind 127.0.0.1 --save "" --appendonly no --dir "$work" > "$work/redis.log" 2>&1 &
redis_pid=$!
for _ in $(seq 1 100); do redis-cli -p "$port" ping > /dev/null 2>&1 && break; sleep 0.05; done
cmake --install "$build" --prefix "$work/prefix" > "$work/install.log"

new_tree() {  # the examples as a user project, in a folder of its own
  local src=$work/$1/src
  mkdir -p "$src"
  for e in particles bloom primary_rays sphere_paths; do cp -r "$root/examples/$e" "$src/$e"; done
  cat > "$src/CMakeLists.txt" <<'CMAKE'
cmake_minimum_required(VERSION 3.25)
project(crossrt_examples C CXX)
set(CMAKE_CXX_STANDARD 17)
find_package(CrossRT REQUIRED)
foreach(example particles bloom primary_rays sphere_paths)
  add_subdirectory(${example})
endforeach()
CMAKE
}
# build TREE LAUNCHER: configures and builds; prints "<translation s> <build s> <translations run>"
build_tree() {
  local t=$work/$1 launcher=$2
  cmake -S "$t/src" -B "$t/build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$work/prefix" \
    -DCROSSRT_REMOTE_STORAGE="redis://127.0.0.1:$port" ${launcher:+-DCMAKE_CXX_COMPILER_LAUNCHER=$launcher} > "$t.configure.log"
  local t0 t1
  t0=$(date +%s%N)
  cmake --build "$t/build" > "$t.build.log" 2>&1 || { tail -30 "$t.build.log"; exit 1; }
  t1=$(date +%s%N)
  # .ninja_log: start ms, end ms, mtime, output, hash; translations write crossrt/<Class>_<Backend>/*.h
  local translate_ms
  translate_ms=$(awk -F'\t' '$4 ~ /\/crossrt\/[^\/]+\/[^\/]+\.h$/ { s += $2 - $1 } END { print s + 0 }' "$t/build/.ninja_log")
  local runs=0
  [ -f "$t/build/crossrtd.log" ] && runs=$(grep -c " translate " "$t/build/crossrtd.log" || true)
  echo "$translate_ms $(( (t1 - t0) / 1000000 )) $runs"
}

if [ $verify_only -eq 0 ]; then
export CCACHE_DIR=$work/ccache CCACHE_BASEDIR=$work
echo "Examples (4 projects, 8 translated classes) against an installed CrossRT, $(nproc) cores; one redis-server."
echo
printf '| %-46s | %14s | %12s | %12s | %10s |\n' "build tree" "translation s" "build s" "translations" "build / A"
printf '|%s|\n' "$(printf -- '-%.0s' {1..110})"
mkdir -p "$root/out"
csv=$root/out/remote_cache.csv
echo "tree,remote_cache,ccache,translation_ms,build_ms,translations_run" > "$csv"
base=0
for row in "A|empty|off|" "B|warm|off|" "C|empty|on|ccache" "D|warm|on|ccache"; do
  IFS='|' read -r name remote cc launcher <<< "$row"
  [ "$name" = C ] && redis-cli -p "$port" FLUSHALL > /dev/null && ccache -C > /dev/null 2>&1
  new_tree "tree-$name"
  read -r tr_ms build_ms runs <<< "$(build_tree "tree-$name" "$launcher")"
  [ "$base" -eq 0 ] && base=$build_ms
  printf '| %-46s | %14.2f | %12.1f | %12d | %10.3f |\n' "$name: remote cache $remote, ccache $cc" \
    "$(echo "$tr_ms / 1000" | bc -l)" "$(echo "$build_ms / 1000" | bc -l)" "$runs" "$(echo "$build_ms / $base" | bc -l)"
  echo "$name,$remote,$cc,$tr_ms,$build_ms,$runs" >> "$csv"
done
echo
echo "translations run: translations the tree's daemon made (0: every class came from the remote cache)."
echo "wrote $csv"
fi

# --- The cost of verifying ---------------------------------------------------------------------
# Each example class translated once into database 1 (no key) and database 2 (signed); then rounds
# of fetching every class from each, interleaved, timing the whole `crossrt translate` (a fresh
# process, as a build runs it) with no daemon to fall back on.
rounds=15
key=$(openssl rand -hex 32)
declare -A classes=([particles]=Particles [bloom]=Bloom [primary_rays]=PrimaryRays [sphere_paths]=SpherePaths)
src=$work/verify/src
mkdir -p "$src"
for e in "${!classes[@]}"; do cp -r "$root/examples/$e" "$src/$e"; done
fetch() {  # fetch EXAMPLE DB [KEY]: prints the wall time in microseconds; fails unless it was a fetch
  local e=$1 class=${classes[$1]} out=$work/verify/out/$1 t0 t1
  rm -rf "$out"
  t0=$(date +%s%N)
  local extra=()  # what crossrt_add_class adds for PrimaryRays' COMPOSE ISceneObject=BVHScene
  [ "$e" = primary_rays ] && extra=(--compose ISceneObject=BVHScene --source "$work/prefix/share/crossrt/sources/BVHScene.cpp")
  CROSSRT_REMOTE_KEY=${3:-} CROSSRT_NO_DAEMON=1 "$work/prefix/bin/crossrt" translate --class "$class" --backend vulkan \
    --out "$out" --source "$src/$e/$class.cpp" "${extra[@]}" --templates "$work/prefix/share/crossrt/templates" \
    --build-dir "$work/verify" --source-root "$src" \
    --remote-storage "redis://127.0.0.1:$port/$2" -- -std=c++17 -I"$work/prefix/include" -I"$work/prefix/include/crossrt" -I"$src/$e" \
    2> "$work/verify/err.txt" || { cat "$work/verify/err.txt" >&2; exit 1; }
  t1=$(date +%s%N)
  echo $(( (t1 - t0) / 1000 ))
}
[ -d "$work/prefix" ] || cmake --install "$build" --prefix "$work/prefix" > "$work/install.log"
declare -A entry_bytes
for e in "${!classes[@]}"; do  # fill both; the largest entry a class adds is its result
  before=$(redis-cli -p "$port" -n 2 --scan | sort)
  fetch "$e" 1 > /dev/null; fetch "$e" 2 "$key" > /dev/null
  entry_bytes[$e]=$(comm -13 <(echo "$before") <(redis-cli -p "$port" -n 2 --scan | sort) |
                    while read -r k; do redis-cli -p "$port" -n 2 STRLEN "$k"; done | sort -n | tail -1)
done
verify_csv=$root/out/remote_cache_verify.csv
echo "class,entry_bytes,round,unsigned_us,signed_us" > "$verify_csv"
echo
echo "Fetching from a warm cache, with and without verifying: $rounds interleaved rounds per class, one process each."
echo "CPU: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//')"
echo
printf '| %-14s | %11s | %16s | %16s | %14s |\n' class "entry KiB" "unsigned ms" "signed ms" "signed / unsigned"
printf '|%s|\n' "$(printf -- '-%.0s' {1..88})"
total_u=0 total_s=0
for e in particles bloom primary_rays sphere_paths; do
  bytes=${entry_bytes[$e]}
  sum_u=0 sum_s=0
  for r in $(seq 1 $rounds); do
    # The order alternates, so that neither side always runs second.
    if (( r % 2 )); then u=$(fetch "$e" 1); s=$(fetch "$e" 2 "$key"); else s=$(fetch "$e" 2 "$key"); u=$(fetch "$e" 1); fi
    grep -q . "$work/verify/err.txt" && { cat "$work/verify/err.txt"; echo "bench_remote_cache: a fetch printed something"; exit 1; }
    sum_u=$((sum_u + u)) sum_s=$((sum_s + s))
    echo "${classes[$e]},$bytes,$r,$u,$s" >> "$verify_csv"
  done
  total_u=$((total_u + sum_u)) total_s=$((total_s + sum_s))
  printf '| %-14s | %11.1f | %16.2f | %16.2f | %17.3f |\n' "${classes[$e]}" "$(echo "$bytes / 1024" | bc -l)" \
    "$(echo "$sum_u / $rounds / 1000" | bc -l)" "$(echo "$sum_s / $rounds / 1000" | bc -l)" "$(echo "$sum_s / $sum_u" | bc -l)"
done
printf '| %-14s | %11s | %16s | %16s | %17.3f |\n' all "" "" "" "$(echo "$total_s / $total_u" | bc -l)"
echo
echo "entry KiB: the class's result entry (generated sources and SPIR-V). wrote $verify_csv"
