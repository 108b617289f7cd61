#!/usr/bin/env bash
# The remote translation cache against real servers on loopback ports, started and stopped here:
# redis-server, and nginx with WebDAV. Two copies of examples/bloom in different folders (two
# build trees) share one server; servers that are down, silent or corrupt; -j 8; read-only
# storage; credentials; ccache hits on the generated sources of the second tree.
#   test/remote/remote_cache.sh CROSSRT SOURCE_ROOT      (exit 77: redis-server or nginx missing)
set -euo pipefail
if [[ $# -lt 2 || "$1" == --help || "$1" == -h ]]; then
  echo "usage: remote_cache.sh CROSSRT SOURCE_ROOT"
  [[ "${1:-}" == --help || "${1:-}" == -h ]]; exit $?
fi
crossrt=$(realpath "$1") root=$(cd "$2" && pwd)
source "$root/test/remote/servers.sh"
redis_port=$(free_port); start_redis "$redis_port"; redis_pid=${pids[-1]}
http_port=$(free_port); start_nginx "$http_port"

stored_entries() {  # stored_entries redis|http: every entry's bytes on that server, one after another
  if [ "$1" = redis ]; then
    for k in $(redis-cli -p "$redis_port" --scan --pattern 'crossrt:*'); do redis-cli -p "$redis_port" --raw GET "$k"; done
  else
    find "$work/dav/cache" -type f -exec cat {} +
  fi
}

for storage in "redis://127.0.0.1:$redis_port" "http://127.0.0.1:$http_port/cache"; do
  kind=${storage%%:*}
  echo "== $kind: two build trees share one server"
  new_tree "tree-$kind-a"; new_tree "tree-$kind-b"
  translate "tree-$kind-a" "$storage" > "$work/out.txt" 2>&1 || { cat "$work/out.txt"; fail "first tree"; }
  [ "$(translations "tree-$kind-a")" -ge 1 ] || fail "the first tree did not translate"
  translate "tree-$kind-b" "$storage" > "$work/out.txt" 2>&1 || { cat "$work/out.txt"; fail "second tree"; }
  [ "$(translations "tree-$kind-b")" -eq 0 ] || fail "the second tree translated instead of fetching"
  grep -q "$work/tree-$kind-b/src/Bloom.h" "$work/tree-$kind-b/build/gen/Bloom.d" || fail "the fetched depfile misses the tree's header"
  ! grep -q "tree-$kind-a" "$work/tree-$kind-b/build/gen/Bloom.d" || fail "the fetched depfile names the other tree"
  # (Through a file: `grep -q` in a pipe ends it early, and the writer's SIGPIPE would turn a match
  # into a pass under pipefail.)
  stored_entries "$kind" > "$work/entries.bin"
  ! grep -a -q "$work" "$work/entries.bin" || fail "an entry holds a path of the machine that made it"
  same_as_local "tree-$kind-b"
  # An edit below the preamble: the manifest's input set no longer matches; translated and stored.
  echo "// edit" >> "$work/tree-$kind-b/src/Bloom.cpp"
  translate "tree-$kind-b" "$storage" > /dev/null 2>&1 || fail "an edited tree"
  [ "$(translations "tree-$kind-b")" -eq 1 ] || fail "an edit did not translate"

  if [ "$kind" = redis ]; then
    # The engine module that --no-daemon loads, rebuilt alone (here: a byte appended): its
    # translations are its own, stored beside the old engine's, not fetched from them.
    echo "== redis: an engine module rebuilt alone does not take the old engine's entries"
    cp "$(dirname "$crossrt")/libcrossrt-engine.so" "$work/engine.so" && printf 'x' >> "$work/engine.so"
    before=$(redis-cli -p "$redis_port" --scan --pattern 'crossrt:*' | wc -l)
    new_tree "tree-engine"
    CROSSRT_ENGINE="$work/engine.so" translate "tree-engine" "$storage" --no-daemon > "$work/out.txt" 2>&1 ||
      { cat "$work/out.txt"; fail "a rebuilt engine module"; }
    after=$(redis-cli -p "$redis_port" --scan --pattern 'crossrt:*' | wc -l)
    [ "$after" -gt "$before" ] || fail "a rebuilt engine module took the old engine's entry ($before entries before, $after after)"
  fi
  echo "== $kind: corrupt entries are ignored and replaced"
  if [ "$kind" = redis ]; then
    for k in $(redis-cli -p "$redis_port" --scan --pattern 'crossrt:*'); do
      v=$(redis-cli -p "$redis_port" --raw GET "$k"); redis-cli -p "$redis_port" SET "$k" "${v:0:200}x${v:210}" > /dev/null
    done
  else
    for f in "$work"/dav/cache/*; do printf 'CROSSRT-REMOTE-CACHE 1 result 0000\ntruncated' > "$f"; done
  fi
  new_tree "tree-$kind-c"
  translate "tree-$kind-c" "$storage" > "$work/out.txt" 2>&1 || { cat "$work/out.txt"; fail "a corrupt entry failed the translation"; }
  [ "$(translations "tree-$kind-c")" -eq 1 ] || fail "a corrupt entry was used"
  same_as_local "tree-$kind-c"
  new_tree "tree-$kind-d"
  translate "tree-$kind-d" "$storage" > /dev/null 2>&1 || fail "after the replacement"
  [ "$(translations "tree-$kind-d")" -eq 0 ] || fail "the corrupt entry was not replaced"

  echo "== $kind: read-only storage is never written"
  if [ "$kind" = redis ]; then redis-cli -p "$redis_port" FLUSHALL > /dev/null; else rm -f "$work"/dav/cache/*; fi
  new_tree "tree-$kind-ro"
  translate "tree-$kind-ro" "$storage|read-only" > /dev/null 2>&1 || fail "read-only"
  [ -z "$(stored_entries "$kind")" ] || fail "read-only storage was written"

  echo "== $kind: -j 8 against one server"
  for round in cold warm; do
    for i in 1 2 3 4 5 6 7 8; do new_tree "tree-$kind-j$round$i"; done
    jobs_=()
    for i in 1 2 3 4 5 6 7 8; do translate "tree-$kind-j$round$i" "$storage" > "$work/j$i.txt" 2>&1 & jobs_+=($!); done
    failed=0; for job in "${jobs_[@]}"; do wait "$job" || failed=1; done
    [ $failed -eq 0 ] || fail "a parallel translation failed ($round)"
    for i in 1 2 3 4 5 6 7 8; do same_as_local "tree-$kind-j$round$i"; done
  done
  [ "$(translations "tree-$kind-jwarm1")" -eq 0 ] || fail "a warm parallel build translated"
done

echo "== http: the Bazel remote cache's layout (<url>/ac/<64 hex digits>)"
new_tree tree-bazel-a; new_tree tree-bazel-b
translate tree-bazel-a "http://127.0.0.1:$http_port/cache|layout=bazel" > /dev/null 2>&1 || fail "bazel layout"
[ "$(find "$work/dav/cache/ac" -type f | grep -c -E '/ac/[0-9a-f]{64}$')" -eq 2 ] || fail "no manifest and result under ac/"
translate tree-bazel-b "http://127.0.0.1:$http_port/cache|layout=bazel" > /dev/null 2>&1 || fail "bazel layout (2)"
[ "$(translations tree-bazel-b)" -eq 0 ] || fail "the bazel layout was not fetched"

echo "== a server that is down, silent, or stops mid-build"
kill "$redis_pid"; wait "$redis_pid" 2> /dev/null || true
new_tree tree-down
translate tree-down "redis://127.0.0.1:$redis_port http://127.0.0.1:$http_port/cache" > "$work/down1.txt" 2>&1 || { cat "$work/down1.txt"; fail "a server down failed the build"; }
grep -q "warning: remote storage redis://127.0.0.1:$redis_port: reading failed" "$work/down1.txt" || { cat "$work/down1.txt"; fail "no warning"; }
[ "$(translations tree-down)" -eq 0 ] || fail "the second storage was not used when the first was down"
echo "// edit" >> "$work/tree-down/src/Bloom.cpp"
translate tree-down "redis://127.0.0.1:$redis_port" > "$work/down2.txt" 2>&1 || fail "a second class in the same build"
! grep -q warning "$work/down2.txt" || fail "a second warning in one build"
same_as_local tree-down
silent_port=$(free_port)
python3 -c "import socket,time; s=socket.socket(); s.bind(('127.0.0.1',$silent_port)); s.listen(16); time.sleep(60)" &
pids+=($!); wait_port "$silent_port"
new_tree tree-silent
start=$(date +%s)
translate tree-silent "http://127.0.0.1:$silent_port/cache|operation-timeout=300" > "$work/silent.txt" 2>&1 || fail "a silent server failed the build"
[ $(( $(date +%s) - start )) -lt 30 ] || fail "a silent server held the build"
grep -q "warning: remote storage http://127.0.0.1:$silent_port/cache" "$work/silent.txt" || fail "no warning for a silent server"
same_as_local tree-silent

echo "== credentials never appear"
secret_port=$(free_port); start_redis "$secret_port" "s3cret-Pass"
new_tree tree-auth-a; new_tree tree-auth-b; new_tree tree-auth-c
translate tree-auth-a "redis://:s3cret-Pass@127.0.0.1:$secret_port" > "$work/auth1.txt" 2>&1 || fail "with a password"
translate tree-auth-b "redis://:s3cret-Pass@127.0.0.1:$secret_port" > "$work/auth2.txt" 2>&1 || fail "with a password (2)"
[ "$(translations tree-auth-b)" -eq 0 ] || fail "the password-protected storage was not used"
translate tree-auth-c "redis://:wr0ng-Pass@127.0.0.1:$secret_port https://user:t0ken-Secret@127.0.0.1:$silent_port/x|connect-timeout=50" \
  > "$work/auth3.txt" 2>&1 || fail "with a wrong password"
grep -q "warning: remote storage redis://\*\*\*@127.0.0.1:$secret_port" "$work/auth3.txt" || { cat "$work/auth3.txt"; fail "no redacted warning"; }
cat "$work"/*.txt "$work"/tree-*/build/crossrtd.log "$work"/tree-*/build/.crossrt-remote-warning > "$work/outputs.all" 2> /dev/null || true
! grep -E -q "s3cret|wr0ng|t0ken" "$work/outputs.all" || fail "a credential appears in an output"

echo "== ccache: the second tree's generated sources hit"
if command -v ccache > /dev/null; then
  export CCACHE_DIR=$work/ccache CCACHE_BASEDIR=$work
  for t in tree-redis-a tree-redis-b; do
    (cd "$work/$t/build" && ccache g++ -std=c++17 -c gen/Bloom_Vulkan_shaders.cpp -o shaders.o)
  done
  hits=$(ccache --print-stats | awk '$1 == "direct_cache_hit" || $1 == "preprocessed_cache_hit" { s += $2 } END { print s + 0 }')
  [ "$hits" -ge 1 ] || { ccache -s; fail "no ccache hit on the second tree"; }
else
  echo "ccache missing: part skipped"
fi
echo "remote_cache: OK"
