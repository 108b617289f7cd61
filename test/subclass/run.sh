#!/usr/bin/env bash
# A user's subclass of a generated class survives regeneration: build examples/custom_kernel,
# edit the base class (a kernel body and the header), rebuild, and check that the subclass still
# compiles, its hand-written kernel still runs, and the regenerated code reflects the edits.
#   run.sh <crossrt source dir> <work dir>
set -euo pipefail
src=$1 work=$2
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work"
cp -r "$src/examples/custom_kernel" "$work/user"
export CROSSRT_DAEMON_IDLE_SECONDS=60
cmake -S "$here" -B "$work/build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCROSSRT_SOURCE_DIR="$src" -DUSER_SOURCE_DIR="$work/user" > "$work/configure.log"
trap '"$work/build/crossrt-build/bin/crossrt" daemon stop --build-dir "$work/build" > /dev/null 2>&1 || true' EXIT
cmake --build "$work/build" --target custom_kernel > "$work/build1.log"
first=$("$work/build/user/custom_kernel")
echo "$first"
echo "$first" | grep -q "original 4.0000, FastVectorOps 4.0000" || { echo "FAIL: first run"; exit 1; }
subclass_stamp=$(stat -c %Y "$work/user/FastVectorOps.cpp")

# Edit the base class: a kernel body, and a new member in the header.
sed -i 's/data\[i\] + m_offset;/data[i] + m_offset * 2.0f;/' "$work/user/VectorOps.cpp"
sed -i 's/  float m_offset = 1.0f;/  float m_offset = 1.0f;\n  int Version() const { return 2; }/' "$work/user/VectorOps.h"
cmake --build "$work/build" --target custom_kernel > "$work/build2.log"
grep -q "translating VectorOps" "$work/build2.log" || { echo "FAIL: the edit did not regenerate"; exit 1; }
grep -q "m_offset \* 2.0" "$work/build/user/crossrt/VectorOps_Vulkan/shaders/kernel1D_Offset.comp" || { echo "FAIL: the regenerated shader misses the edit"; exit 1; }
[ "$(stat -c %Y "$work/user/FastVectorOps.cpp")" = "$subclass_stamp" ] || { echo "FAIL: the user's subclass file was touched"; exit 1; }
second=$("$work/build/user/custom_kernel")
echo "$second"
echo "$second" | grep -q "original 5.0000, FastVectorOps 5.0000" || { echo "FAIL: the edit is not in the result"; exit 1; }
echo "$second" | grep -q "hand-written kernel dispatches: 1" || { echo "FAIL: the override did not run"; exit 1; }
echo "OK: the subclass survived regeneration"
