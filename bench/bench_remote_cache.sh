#!/usr/bin/env bash
# Benchmark of the remote translation cache (a program that prints a table, not a test).
# The examples (particles, bloom, primary_rays, sphere_paths) as a project outside the CrossRT
# tree, built against an installed CrossRT in four build trees, each in a folder of its own and
# each from its own copy of the sources, sharing one redis-server on a loopback port:
#   A: empty remote cache; B: warm remote cache (A's translations);
#   C, D: the same two with ccache on the compiler (CCACHE_BASEDIR, empty ccache before C).
# Translation time is the sum of the translation steps' times in .ninja_log; build time is the wall
# time of `cmake --build`. Writes out/remote_cache.csv.
#   bench/bench_remote_cache.sh [BUILD_DIR (default build)]
set -euo pipefail
if [[ "${1:-}" == --help || "${1:-}" == -h ]]; then
  echo "usage: bench/bench_remote_cache.sh [BUILD_DIR (default build)]"
  echo "  Clean builds of the examples with an empty and a warm remote translation cache (Redis),"
  echo "  with and without ccache; prints a table and writes out/remote_cache.csv."
  exit 0
fi
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
