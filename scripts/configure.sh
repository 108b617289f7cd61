# Sourced by run-example.sh and run-tests.sh: installs what is missing, configures build/ in the
# repository root, and stops the build's translation daemon when the calling script ends.
cd "$(dirname "${BASH_SOURCE[0]}")/.."
./scripts/install-deps.sh
# Lavapipe with ray tracing (Mesa 25), in .deps/ only: the tests run on it, the system keeps its drivers.
./scripts/install-lavapipe-rt.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
if ! grep -q '^CROSSRT_ISPC_EXECUTABLE:FILEPATH=/' build/CMakeCache.txt; then
  echo "note: no ISPC compiler found (ispc on PATH, or -DCROSSRT_ISPC_EXECUTABLE): the _ISPC classes, their tests and" \
       "benchmark columns are skipped; the README says how to install ISPC" >&2
fi
root=$(pwd)
trap '[ -x "$root/build/bin/crossrt" ] && "$root/build/bin/crossrt" daemon stop --build-dir "$root/build" > /dev/null 2>&1; true' EXIT
