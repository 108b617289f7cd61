# Sourced by run-example.sh and run-tests.sh: installs what is missing, configures build/ in the
# repository root, and stops the build's translation daemon when the calling script ends.
cd "$(dirname "${BASH_SOURCE[0]}")/.."
./scripts/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
root=$(pwd)
trap '[ -x "$root/build/bin/crossrt" ] && "$root/build/bin/crossrt" daemon stop --build-dir "$root/build" > /dev/null 2>&1; true' EXIT
