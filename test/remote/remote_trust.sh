#!/usr/bin/env bash
# Trust in the remote translation cache, against real servers on loopback ports (redis-server,
# nginx with WebDAV, and nginx over https with a certificate authority made here). With a team key
# every entry is signed; this plays the one who can write to the store but holds no key:
#   - entries signed with the key are shared between two build trees (redis, http, https);
#   - a poisoned entry written straight into the store reaches a build without a key (what the
#     docs say a store without a key trusts), and is rejected by a build with one;
#   - so is an entry signed with another key, and a poisoned body under a copied signature;
#   - a truncated entry is ignored; a store that answers garbage or slowly never fails a build;
#   - every rejection warns, names the storage and the key, and `crossrt daemon status` counts it;
#   - https checks certificates; a key that is too short turns the cache off, with a warning.
# In every case where the entry is not used, the output is byte-identical to a local translation.
#   test/remote/remote_trust.sh CROSSRT SOURCE_ROOT      (exit 77: redis-server or nginx missing)
set -euo pipefail
if [[ $# -lt 2 || "$1" == --help || "$1" == -h ]]; then
  echo "usage: remote_trust.sh CROSSRT SOURCE_ROOT"
  [[ "${1:-}" == --help || "${1:-}" == -h ]]; exit $?
fi
crossrt=$(realpath "$1") root=$(cd "$2" && pwd)
source "$root/test/remote/servers.sh"
redis_port=$(free_port); start_redis "$redis_port"
http_port=$(free_port); https_port=$(free_port); start_nginx "$http_port" "$https_port"
key_a=$(openssl rand -hex 32) key_b=$(openssl rand -hex 32)
printf '%s\n' "$key_a" > "$work/team.key"

# The store seen as an attacker sees it: entries by key, read and written byte for byte.
entry_keys() {  # entry_keys KIND: every stored key
  if [ "$1" = redis ]; then redis-cli -p "$redis_port" --scan --pattern 'crossrt:*' | sed 's/^crossrt://'
  else find "$work/dav/cache" -type f -printf '%f\n'; fi
}
get_entry() {  # get_entry KIND KEY FILE
  if [ "$1" = redis ]; then redis-cli -p "$redis_port" --raw GET "crossrt:$2" | head -c -1 > "$3"
  else cp "$work/dav/cache/$2" "$3"; fi
}
put_entry() {  # put_entry KIND KEY FILE
  if [ "$1" = redis ]; then redis-cli -p "$redis_port" -x SET "crossrt:$2" < "$3" > /dev/null
  else cp "$3" "$work/dav/cache/$2"; fi
}
keys_of() {  # keys_of KIND manifest|result: the keys whose entries are of that kind
  local k
  for k in $(entry_keys "$1"); do
    get_entry "$1" "$k" "$work/probe"
    head -c 200 "$work/probe" | head -1 | grep -q "^CROSSRT-REMOTE-CACHE 1 $2 " && echo "$k"
  done
  return 0
}
# rejected TREE OUTPUT WHY: the translation warned of a rejection, translated locally, and
# recorded it for `crossrt daemon status`
rejected() {
  grep -q "warning: remote storage .*: rejected the result entry for class 'Bloom' (vulkan): $3.*key $id_a" "$2" \
    || { cat "$2"; fail "$1: no rejection warning saying '$3'"; }
  [ "$(translations "$1")" -eq 1 ] || fail "$1: a rejected entry was used"
  "$crossrt" daemon status --build-dir "$work/$1/build" > "$work/status.txt" || fail "$1: daemon status"
  grep -q "remote cache    1 entry rejected; the last: .*$3" "$work/status.txt" || { cat "$work/status.txt"; fail "$1: daemon status does not count it"; }
  same_as_local "$1"
}

for storage in "redis://127.0.0.1:$redis_port" "http://127.0.0.1:$http_port/cache"; do
  kind=${storage%%:*}
  echo "== $kind: entries signed with the team key are shared"
  new_tree "tree-$kind-a"; new_tree "tree-$kind-b"
  translate "tree-$kind-a" "$storage" --remote-key-file "$work/team.key" > "$work/out.txt" 2>&1 || { cat "$work/out.txt"; fail "first tree"; }
  CROSSRT_REMOTE_KEY=$key_a translate "tree-$kind-b" "$storage" > "$work/out.txt" 2>&1 || { cat "$work/out.txt"; fail "second tree"; }
  [ "$(translations "tree-$kind-b")" -eq 0 ] || fail "entries signed with the same key were not shared"
  same_as_local "tree-$kind-b"
  good=$(keys_of "$kind" result) manifest=$(keys_of "$kind" manifest)
  [ -n "$good" ] && [ -n "$manifest" ] || fail "no entries stored"
  get_entry "$kind" "$good" "$work/good"; get_entry "$kind" "$manifest" "$work/manifest"
  id_a=$(head -1 "$work/good" | sed -n 's/.* hmac-sha256:\([0-9a-f]\{16\}\):[0-9a-f]\{64\}$/\1/p')
  [ -n "$id_a" ] || { head -1 "$work/good"; fail "a stored entry is not signed"; }
  head -1 "$work/manifest" | grep -q " hmac-sha256:$id_a:" || fail "a stored manifest is not signed"

  echo "== $kind: a poisoned entry reaches a build without a key, and no build with one"
  # The attacker translates a class of their own making with the same options, without a key, and
  # writes its result over the team's: the team's signed manifest still points there.
  new_tree "tree-$kind-evil"
  sed -i 's/- m_threshold, 0.0f/- m_threshold - 12345.0f, 0.0f/' "$work/tree-$kind-evil/src/Bloom.cpp"
  translate "tree-$kind-evil" "$storage" > /dev/null 2>&1 || fail "the attacker's translation"
  grep -rq 12345 "$work/tree-$kind-evil/build/gen" || fail "the attacker's edit does not show in the generated code"
  evil=$(keys_of "$kind" result | grep -v -x "$good" | head -1)
  [ -n "$evil" ] || fail "the attacker's entry was not stored"
  get_entry "$kind" "$evil" "$work/evil"
  ! head -1 "$work/evil" | grep -q hmac-sha256 || fail "an entry stored without a key is signed"
  put_entry "$kind" "$manifest" "$work/manifest"; put_entry "$kind" "$good" "$work/evil"
  new_tree "tree-$kind-nokey"
  translate "tree-$kind-nokey" "$storage" > /dev/null 2>&1 || fail "a build without a key"
  grep -rq 12345 "$work/tree-$kind-nokey/build/gen" || fail "the poisoned entry did not reach a build without a key (the test's attack is broken)"
  new_tree "tree-$kind-unsigned"
  translate "tree-$kind-unsigned" "$storage" --remote-key-file "$work/team.key" > "$work/out.txt" 2>&1 || fail "an unsigned entry failed the build"
  rejected "tree-$kind-unsigned" "$work/out.txt" "it is not signed"

  echo "== $kind: an entry signed with another key is rejected"
  new_tree "tree-$kind-evil-b"
  cp "$work/tree-$kind-evil/src/Bloom.cpp" "$work/tree-$kind-evil-b/src/"
  CROSSRT_REMOTE_KEY=$key_b translate "tree-$kind-evil-b" "$storage" > /dev/null 2>&1 || fail "the attacker's translation with another key"
  get_entry "$kind" "$evil" "$work/evil-b"
  head -1 "$work/evil-b" | grep -q hmac-sha256 || fail "the other key's entry is not signed"
  put_entry "$kind" "$manifest" "$work/manifest"; put_entry "$kind" "$good" "$work/evil-b"
  new_tree "tree-$kind-otherkey"
  CROSSRT_REMOTE_KEY_FILE=$work/team.key translate "tree-$kind-otherkey" "$storage" > "$work/out.txt" 2>&1 || fail "another key's entry failed the build"
  rejected "tree-$kind-otherkey" "$work/out.txt" "it is signed with another key"

  echo "== $kind: a poisoned body under the team's signature is rejected"
  { printf '%s %s\n' "$(head -1 "$work/evil" | cut -d' ' -f1-4)" "$(head -1 "$work/good" | cut -d' ' -f5)"; tail -n +2 "$work/evil"; } > "$work/forged"
  put_entry "$kind" "$manifest" "$work/manifest"; put_entry "$kind" "$good" "$work/forged"
  new_tree "tree-$kind-forged"
  CROSSRT_REMOTE_KEY=$key_a translate "tree-$kind-forged" "$storage" > "$work/out.txt" 2>&1 || fail "a forged entry failed the build"
  rejected "tree-$kind-forged" "$work/out.txt" "its signature does not match its contents"

  echo "== $kind: a truncated entry is ignored"
  head -c 300 "$work/good" > "$work/truncated"
  put_entry "$kind" "$manifest" "$work/manifest"; put_entry "$kind" "$good" "$work/truncated"
  new_tree "tree-$kind-truncated"
  CROSSRT_REMOTE_KEY=$key_a translate "tree-$kind-truncated" "$storage" > "$work/out.txt" 2>&1 || fail "a truncated entry failed the build"
  [ "$(translations "tree-$kind-truncated")" -eq 1 ] || fail "a truncated entry was used"
  ! grep -q warning "$work/out.txt" || { cat "$work/out.txt"; fail "a truncated entry warned"; }
  same_as_local "tree-$kind-truncated"
  # The local translations above stored signed entries again: the next build with the key fetches.
  new_tree "tree-$kind-again"
  CROSSRT_REMOTE_KEY=$key_a translate "tree-$kind-again" "$storage" > /dev/null 2>&1 || fail "after the replacement"
  [ "$(translations "tree-$kind-again")" -eq 0 ] || fail "the rejected entry was not replaced by a signed one"
done

echo "== https: certificates are checked"
https="https://127.0.0.1:$https_port/cache"
# The TLS handshake counts against connect-timeout (100 ms by default); on a loaded machine nginx
# may not answer it that fast, and this part is about certificates, not time.
slow_ok="connect-timeout=10000"
new_tree tree-https-a; new_tree tree-https-b; new_tree tree-https-untrusted
CROSSRT_REMOTE_KEY=$key_a translate tree-https-a "$https|ca-file=$work/tls/ca.pem|$slow_ok" > "$work/out.txt" 2>&1 || { cat "$work/out.txt"; fail "https"; }
! grep -q warning "$work/out.txt" || { cat "$work/out.txt"; fail "https with the test's authority warned"; }
CROSSRT_REMOTE_KEY=$key_a translate tree-https-b "$https|ca-file=$work/tls/ca.pem|$slow_ok" > /dev/null 2>&1 || fail "https (2)"
[ "$(translations tree-https-b)" -eq 0 ] || fail "https entries were not shared"
same_as_local tree-https-b
CROSSRT_REMOTE_KEY=$key_a translate tree-https-untrusted "$https|$slow_ok" > "$work/out.txt" 2>&1 || fail "an untrusted certificate failed the build"
grep -q "warning: remote storage $https: reading failed (.*certificate" "$work/out.txt" || { cat "$work/out.txt"; fail "no warning for an untrusted certificate"; }
[ "$(translations tree-https-untrusted)" -eq 1 ] || fail "an entry was read from a server whose certificate is not trusted"

echo "== stores that answer garbage or slowly"
garbage_port=$(free_port) slow_port=$(free_port)
python3 - "$garbage_port" "$slow_port" > /dev/null 2>&1 <<'PY' &
import os, socket, sys, threading, time
def serve(port, answer):
    s = socket.socket(); s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1); s.bind(("127.0.0.1", port)); s.listen(16)
    while True:
        c, _ = s.accept(); threading.Thread(target=answer, args=(c,), daemon=True).start()
def garbage(c):
    try: c.recv(65536); c.sendall(b"$99999999\r\n" + os.urandom(4096) + b"HTTP/1.1 200 OK\r\nContent-Length: 5\r\n\r\n\xff\xfe"); c.close()
    except OSError: pass
def slow(c):
    try:
        c.recv(65536)
        for b in b"HTTP/1.1 200 OK\r\nContent-Length: 100000\r\n\r\n" + b"x" * 100: c.sendall(bytes([b])); time.sleep(0.5)
    except OSError: pass
threading.Thread(target=serve, args=(int(sys.argv[1]), garbage), daemon=True).start()
threading.Thread(target=serve, args=(int(sys.argv[2]), slow), daemon=True).start()
time.sleep(120)
PY
pids+=($!); wait_port "$garbage_port"; wait_port "$slow_port"
for storage in "redis://127.0.0.1:$garbage_port" "http://127.0.0.1:$garbage_port/cache" \
               "redis://127.0.0.1:$slow_port|operation-timeout=300" "http://127.0.0.1:$slow_port/cache|operation-timeout=300"; do
  name=tree-bad-$(echo "$storage" | tr -c 'a-z0-9' '-')
  new_tree "$name"
  start=$(date +%s)
  CROSSRT_REMOTE_KEY=$key_a translate "$name" "$storage" > "$work/out.txt" 2>&1 || { cat "$work/out.txt"; fail "$storage failed the build"; }
  [ $(( $(date +%s) - start )) -lt 30 ] || fail "$storage held the build"
  grep -q "warning: remote storage ${storage%%|*}" "$work/out.txt" || { cat "$work/out.txt"; fail "no warning for $storage"; }
  [ "$(translations "$name")" -eq 1 ] || fail "$storage: not translated locally"
done
same_as_local "$name"

echo "== a key that cannot be used turns the cache off; the key is never an option"
new_tree tree-shortkey
printf 'too-short\n' > "$work/short.key"
before=$(entry_keys redis | wc -l)
translate tree-shortkey "redis://127.0.0.1:$redis_port" --remote-key-file "$work/short.key" > "$work/out.txt" 2>&1 || fail "a short key failed the build"
grep -q "warning: remote cache key: the key file '$work/short.key' holds 9 characters; a key needs at least 32" "$work/out.txt" || { cat "$work/out.txt"; fail "no warning for a short key"; }
[ "$(entry_keys redis | wc -l)" -eq "$before" ] || fail "a build with an unusable key wrote to the store"
same_as_local tree-shortkey
set +e; translate tree-shortkey "redis://127.0.0.1:$redis_port" --remote-key "$key_a" > "$work/out.txt" 2>&1; rc=$?; set -e
[ $rc -eq 2 ] && grep -q "never given on the command line" "$work/out.txt" || { cat "$work/out.txt"; fail "--remote-key was accepted"; }
! grep -rq -e "$key_a" -e "$key_b" "$work"/*.txt "$work"/tree-*/build/crossrtd.log "$work"/tree-*/build/.crossrt-remote-* 2> /dev/null \
  || fail "a key appears in an output"
echo "remote_trust: OK"
