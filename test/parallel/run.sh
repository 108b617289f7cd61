#!/usr/bin/env bash
# Translates 8 classes with `cmake --build -j 8` through one daemon, then again serially and
# in-process, and requires byte-identical generated files.
#   run.sh <crossrt source dir> <work dir>
set -euo pipefail
src=$1 work=$2
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work"
export CROSSRT_DAEMON_IDLE_SECONDS=60
cmake -S "$here" -B "$work/build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCROSSRT_SOURCE_DIR="$src" > "$work/configure.log"
cmake --build "$work/build" --target crossrt crossrtd > "$work/tools.log"
trap '"$work/build/crossrt-build/bin/crossrt" daemon stop --build-dir "$work/build" > /dev/null || true' EXIT

cmake --build "$work/build" --target crossrt_generate -j 8 > "$work/parallel.log"
served=$("$work/build/crossrt-build/bin/crossrt" daemon status --json --build-dir "$work/build" | grep '"translations"' | tr -dc 0-9)
echo "daemon translations: $served"
[ "$served" -ge 8 ] || { echo "FAIL: the daemon served $served translations, expected 8"; exit 1; }
grep -q "in-process" "$work/parallel.log" && { echo "FAIL: some jobs fell back to in-process translation"; exit 1; }
mkdir -p "$work/parallel"
cp -r "$work/build/crossrt" "$work/parallel/"

rm -rf "$work/build/crossrt"
CROSSRT_NO_DAEMON=1 cmake --build "$work/build" --target crossrt_generate -j 1 > "$work/serial.log"
if diff -r -x '.crossrt-manifest.json' -x '*.d' "$work/parallel/crossrt" "$work/build/crossrt"; then
  echo "OK: $(find "$work/build/crossrt" -type f ! -name '*.d' ! -name '.crossrt-manifest.json' | wc -l) generated files identical"
else
  echo "FAIL: parallel and serial outputs differ"
  exit 1
fi
