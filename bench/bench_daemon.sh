#!/usr/bin/env bash
# Benchmark of the translation daemon (a program that prints a table, not a test).
# Cold: a new crossrt process translating in-process, no daemon. Warm: the build tree's daemon
# after one translation. Scenarios edit a copy of examples/bloom. Each figure is the median of 5.
#   bench/bench_daemon.sh [build dir]     (default: build)
set -euo pipefail
if [[ "${1:-}" == --help || "${1:-}" == -h ]]; then
  echo "usage: bench/bench_daemon.sh [BUILD_DIR (default build)]"
  echo "  Cold against warm translation times of examples/bloom, per edit scenario (medians of 5)."
  exit 0
fi
root=$(cd "$(dirname "$0")/.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
crossrt=$build/bin/crossrt
work=$(mktemp -d)
trap '"$crossrt" daemon stop --build-dir "$work" > /dev/null 2>&1 || true; cp "$work/crossrtd.log" "$build/bench_daemon.log" 2>/dev/null || true; rm -rf "$work"' EXIT
cp "$root/examples/bloom/Bloom.h" "$root/examples/bloom/Bloom.cpp" "$work/"

args=(translate --class Bloom --backend vulkan --out "$work/gen" --source "$work/Bloom.cpp"
      --templates "$root/templates")
flags=(-- -I"$root/libs/litemath" -I"$work")
now_ms() { echo $(( $(date +%s%N) / 1000000 )); }
# time_ms <command...>: wall milliseconds of one run
time_ms() { local t0; t0=$(now_ms); "$@" > /dev/null 2>&1 || { echo "bench: command failed: $*" >&2; exit 1; }; echo $(( $(now_ms) - t0 )); }
median() { printf '%s\n' "$@" | sort -n | sed -n "$(( ($# + 1) / 2 ))p"; }

edit() {  # applies scenario $1, edit number $2, to the copy
  case $1 in
    kernel)  sed -i -E "s/m_strength( \* [0-9.]+f)?;/m_strength * 1.0$2f;/" "$work/Bloom.cpp" ;;  # a new constant each time
    header)  echo "inline int BloomHeaderEdit$2() { return $2; }" >> "$work/Bloom.h" ;;
    comment) echo "// comment edit $2" >> "$work/Bloom.cpp" ;;
    none)    ;;
  esac
}

cold() {  # new process, no daemon, no manifest
  local t=()
  for i in 1 2 3 4 5; do edit "$1" "$i"; rm -rf "$work/gen"; t+=("$(time_ms "$crossrt" "${args[@]}" --no-daemon "${flags[@]}")"); done
  median "${t[@]}"
}
warm() {  # the daemon of $work, already holding this class's AST
  local t=()
  "$crossrt" "${args[@]}" --build-dir "$work" "${flags[@]}" > /dev/null 2>&1
  for i in 1 2 3 4 5; do
    edit "$1" "$((i + 5))"
    [ "$1" = none ] && [ "${2:-}" = reparse ] && rm -f "$work/gen/.crossrt-manifest.json"
    t+=("$(time_ms "$crossrt" "${args[@]}" --build-dir "$work" "${flags[@]}")")
  done
  median "${t[@]}"
}

echo "Translating Bloom (3 kernels, Vulkan backend) on $(nproc) cores; medians of 5 runs, wall ms."
echo
printf '| %-44s | %8s | %8s | %8s |\n' "scenario" "cold ms" "warm ms" "warm/cold"
printf '|%s|\n' "$(printf -- '-%.0s' {1..79})"
row() { printf '| %-44s | %8d | %8d | %8.3f |\n' "$1" "$2" "$3" "$(echo "$3 / $2" | bc -l)"; }
c=$(cold none); w=$(warm none);          row "no change (warm: manifest, daemon not asked)" "$c" "$w"
w=$(warm none reparse);                   row "no change, manifest removed (daemon reparse)" "$c" "$w"
c=$(cold kernel); w=$(warm kernel);      row "kernel body edit" "$c" "$w"
c=$(cold header); w=$(warm header);      row "header edit (user part of preamble rebuilt)" "$c" "$w"
c=$(cold comment); w=$(warm comment);    row "comment-only edit (outputs byte-identical)" "$c" "$w"

# A no-op build of an example: nothing changed, nothing runs.
cmake --build "$build" --target bloom > /dev/null
t=(); for i in 1 2 3 4 5; do t+=("$(time_ms cmake --build "$build" --target bloom)"); done
noop=$(median "${t[@]}")
echo
echo "no-op 'cmake --build --target bloom' (2 translated classes): ${noop} ms, $(( noop / 2 )) ms per class"
"$crossrt" daemon status --build-dir "$work" | sed -n '1p;/cached ASTs/p;/AST hit rate/p;/preambles/p'
