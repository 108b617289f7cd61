#!/usr/bin/env bash
# Builds and runs the user project of this folder against CrossRT.
#   run.sh install <crossrt build dir> <work dir>   : cmake --install, then find_package(CrossRT)
#   run.sh subdirectory <crossrt source dir> <work dir> : add_subdirectory(crossrt)
#   run.sh duplicate <crossrt build dir> <work dir>  : a class translated twice under one name is a
#                                                      configure error that names NAME
#   run.sh remote-options <crossrt build dir> <work dir> : CROSSRT_REMOTE_STORAGE and
#                                                      CROSSRT_REMOTE_KEY_FILE reach every translation
set -euo pipefail
mode=$1 crossrt=$2 work=$3
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work"
export CROSSRT_DAEMON_IDLE_SECONDS=60
# The daemon this build starts goes when the test ends.
trap 'for c in "$work"/prefix/bin/crossrt "$work"/build/crossrt/bin/crossrt; do [ -x "$c" ] && "$c" daemon stop --build-dir "$work/build" > /dev/null 2>&1; done; true' EXIT
if [ "$mode" = duplicate ]; then
  cmake --install "$crossrt" --prefix "$work/prefix" > "$work/install.log"
  if cmake -S "$here" -B "$work/build" -G Ninja -DCMAKE_PREFIX_PATH="$work/prefix" -DTRANSLATE_TWICE=ON > "$work/configure.log" 2>&1; then
    echo "configuring a project that translates Heat twice under one name succeeded" >&2
    exit 1
  fi
  if ! grep -q "Heat_CPU is already generated in" "$work/configure.log" || ! grep -q "NAME" "$work/configure.log"; then
    echo "the configure error does not say that Heat_CPU is generated twice and what NAME does:" >&2
    cat "$work/configure.log" >&2
    exit 1
  fi
  echo "package $mode: OK"
  exit 0
fi
if [ "$mode" = remote-options ]; then
  # The key file's path reaches the translations; the key never does (it is not in the build).
  cmake --install "$crossrt" --prefix "$work/prefix" > "$work/install.log"
  printf 'k3y-never-in-the-build-0123456789abcdef\n' > "$work/team.key"
  cmake -S "$here" -B "$work/build" -G Ninja -DCMAKE_PREFIX_PATH="$work/prefix" \
    -DCROSSRT_REMOTE_STORAGE="redis://127.0.0.1:1|read-only" -DCROSSRT_REMOTE_KEY_FILE="$work/team.key" > "$work/configure.log"
  translations=$(grep -c "crossrt translate" "$work/build/build.ninja" || true)
  with_key=$(grep "crossrt translate" "$work/build/build.ninja" | grep -c -E -- "--remote-storage \"?redis://127.0.0.1:1\|read-only\"? --remote-key-file $work/team.key" || true)
  if [ "$translations" -eq 0 ] || [ "$with_key" -ne "$translations" ]; then
    echo "$with_key of $translations translation commands get the remote storage and the key file" >&2
    exit 1
  fi
  if grep -rq k3y-never "$work/build"; then echo "the key itself is in the build tree" >&2; exit 1; fi
  echo "package $mode: OK"
  exit 0
fi
if [ "$mode" = install ]; then
  cmake --install "$crossrt" --prefix "$work/prefix" > "$work/install.log"
  cmake -S "$here" -B "$work/build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$work/prefix"
else
  cmake -S "$here" -B "$work/build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCROSSRT_SOURCE_DIR="$crossrt"
fi
cmake --build "$work/build"
# Built once, the project is up to date: no translation reruns (every input in the depfiles exists).
ninja -C "$work/build" -n > "$work/dry-run.log"  # (grep -q in a pipe: ninja's SIGPIPE fails the pipe)
if grep -q "CrossRT: translating" "$work/dry-run.log"; then
  echo "a second build translates again:" >&2
  ninja -C "$work/build" -d explain -n 2>&1 | head -5 >&2
  exit 1
fi
"$work/build/app"
# Its OpenMP threads sleep after a parallel region (libcrossrt_openmp_waits.so, after libgomp).
env -u OMP_WAIT_POLICY -u GOMP_SPINCOUNT OMP_DISPLAY_ENV=verbose "$work/build/app" > "$work/app-omp.log" 2>&1
if ! grep -q "GOMP_SPINCOUNT = '0'" "$work/app-omp.log"; then
  echo "the project's app keeps libgomp's spinning: libcrossrt_openmp_waits.so is missing or before libgomp:" >&2
  readelf -d "$work/build/app" | grep NEEDED >&2
  exit 1
fi
if [ "$mode" = install ]; then
  # The app installed elsewhere starts: it finds libcrossrt_openmp_waits.so in CrossRT's prefix.
  cmake --install "$work/build" --prefix "$work/app-prefix" > "$work/app-install.log"
  if ! "$work/app-prefix/bin/app" > "$work/app-installed.log" 2>&1; then
    echo "the installed app does not run:" >&2
    cat "$work/app-installed.log" >&2
    exit 1
  fi
  # An upgraded CrossRT (here its engine, newer) translates the classes again, though the client
  # and the sources did not change.
  touch "$work/prefix/lib/crossrt/libcrossrt-engine.so"
  ninja -C "$work/build" -n > "$work/dry-run.log"
  if ! grep -q "CrossRT: translating" "$work/dry-run.log"; then
    echo "a newer installed engine does not translate the classes again" >&2
    exit 1
  fi
fi
# Last, so that the test passes only here (CTest ignores the exit code where it reads the output).
echo "package $mode: OK"
