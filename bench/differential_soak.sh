#!/usr/bin/env bash
# The differential tester's soak: random classes (test/differential/generate.py) in batches, each
# built as _CPU, _Vulkan and _ISPC in the build tree's test/differential folder and run against the
# class as written, the _ISPC kernels both in SIMD lanes and as their scalar loops. Prints a line
# per batch and a summary: classes tried, batches that did not build (a refusal or generated code
# that does not compile: each a bug, loud rather than silent), and mismatches (silent wrong
# answers). The build tree is set back to CTest's seeds at the end.
#   bench/differential_soak.sh [BUILD_DIR (default build)] [FIRST_SEED (default 1000)] [CLASSES (default 200)] [BATCH (default 20)]
set -uo pipefail
if [ "${1:-}" = "--help" ] || [ "${1:-}" = "-h" ]; then
  sed -n '2,8p' "$0" | sed 's/^# \{0,1\}//'
  exit 0
fi
build=${1:-build} first=${2:-1000} classes=${3:-200} batch=${4:-20}
[ -f "$build/CMakeCache.txt" ] || { echo "differential_soak: $build is not a configured CrossRT build tree" >&2; exit 2; }
log=$(mktemp -d)
tried=0 broken=0 mismatches=0 agreements=0
restore() { cmake -S . -B "$build" -DCROSSRT_DIFFERENTIAL_FIRST=1 -DCROSSRT_DIFFERENTIAL_COUNT=10 > /dev/null; }
trap restore EXIT
for ((seed = first; seed < first + classes; seed += batch)); do
  n=$((first + classes - seed < batch ? first + classes - seed : batch))
  cmake -S . -B "$build" -DCROSSRT_DIFFERENTIAL_FIRST=$seed -DCROSSRT_DIFFERENTIAL_COUNT=$n > "$log/configure.log" 2>&1 || { cat "$log/configure.log"; exit 1; }
  tried=$((tried + n))
  if ! cmake --build "$build" --target crossrt_differential > "$log/build_$seed.log" 2>&1; then
    broken=$((broken + 1))
    echo "seeds $seed..$((seed + n - 1)): did not build:"
    grep -E "error:" "$log/build_$seed.log" | sort -u | head -5
    continue
  fi
  # Twice: the _ISPC classes' kernels in SIMD lanes (a class runs once, too few calls to leave
  # them), and as their scalar loops (crossrt::LaneChoice).
  for lanes in measure never; do
    out=$(CROSSRT_ISPC_LANES=$lanes "$build/test/differential/crossrt_differential" 2>&1)
    echo "$out" | grep MISMATCH
    summary=$(echo "$out" | tail -1)
    echo "seeds $seed..$((seed + n - 1)), ISPC lanes $lanes: $summary"
    agreements=$((agreements + $(echo "$summary" | awk '{print $1}')))
    mismatches=$((mismatches + $(echo "$summary" | awk '{print $3}')))
  done
done
echo "differential soak: $tried random classes from seed $first; $broken batches did not build; $agreements backend runs agreed, $mismatches mismatched"
[ "$broken" -eq 0 ] && [ "$mismatches" -eq 0 ]
