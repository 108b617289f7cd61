# Shared by the remote cache tests (sourced, not run): real servers on loopback ports, started and
# stopped by the test, and copies of examples/bloom in folders of their own (build trees).
# The sourcing script sets `crossrt` and `root` (the CrossRT source tree) first; this sets `work`
# (a temporary folder, removed on exit) and `pids` (the servers, killed on exit).
for tool in redis-server redis-cli nginx; do
  command -v "$tool" > /dev/null || { echo "remote_cache: $tool is not installed (scripts/install-deps.sh installs it); skipped"; exit 77; }
done
work=$(mktemp -d /tmp/crossrt-remote.XXXXXX)
pids=()
cleanup() {
  for t in "$work"/tree*; do [ -d "$t/build" ] && "$crossrt" daemon stop --build-dir "$t/build" > /dev/null 2>&1; done
  for p in "${pids[@]}"; do kill "$p" 2> /dev/null || true; done
  wait 2> /dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT
fail() { echo "remote_cache: FAILED: $*"; exit 1; }
export CROSSRT_DAEMON_IDLE_SECONDS=60
unset CROSSRT_REMOTE_STORAGE CROSSRT_REMOTE_KEY CROSSRT_REMOTE_KEY_FILE

free_port() {  # a loopback port nothing listens on
  local p
  for _ in $(seq 1 50); do
    p=$((20000 + RANDOM % 20000))
    (exec 3<> "/dev/tcp/127.0.0.1/$p") 2> /dev/null || { echo "$p"; return; }
  done
  fail "no free port"
}
wait_port() { for _ in $(seq 1 100); do (exec 3<> "/dev/tcp/127.0.0.1/$1") 2> /dev/null && return; sleep 0.05; done; fail "nothing listens on $1"; }

start_redis() {  # start_redis PORT [PASSWORD]
  redis-server --port "$1" --bind 127.0.0.1 --save "" --appendonly no --dir "$work" ${2:+--requirepass "$2"} \
    > "$work/redis-$1.log" 2>&1 &
  pids+=($!)
  wait_port "$1"
}

# start_nginx PORT [TLS_PORT]: nginx with WebDAV under /cache/ (files in $work/dav/cache); with
# TLS_PORT, also https on that port, with a certificate for 127.0.0.1 and localhost signed by a
# certificate authority made here ($work/tls/ca.pem).
start_nginx() {
  local tls=""
  mkdir -p "$work/dav/cache" "$work/nginx"
  if [ -n "${2:-}" ]; then
    command -v openssl > /dev/null || fail "openssl is not installed (scripts/install-deps.sh installs it)"
    mkdir -p "$work/tls" && (
      cd "$work/tls"
      openssl req -x509 -newkey rsa:2048 -nodes -keyout ca.key -out ca.pem -days 2 -subj "/CN=CrossRT test CA" 2> /dev/null
      openssl req -newkey rsa:2048 -nodes -keyout server.key -out server.csr -subj "/CN=127.0.0.1" 2> /dev/null
      printf 'subjectAltName=IP:127.0.0.1,DNS:localhost\n' > san.ext
      openssl x509 -req -in server.csr -CA ca.pem -CAkey ca.key -CAcreateserial -out server.pem -days 2 -extfile san.ext 2> /dev/null
    ) || fail "cannot make the test certificates"
    tls="server {
    listen 127.0.0.1:$2 ssl;
    ssl_certificate $work/tls/server.pem;
    ssl_certificate_key $work/tls/server.key;
    root $work/dav;
    location /cache/ { dav_methods PUT DELETE; create_full_put_path on; client_max_body_size 64m; }
  }"
  fi
  cat > "$work/nginx.conf" <<CONF
daemon off;
master_process off;  # one process, as the user running the test (workers would drop to nobody)
pid $work/nginx/nginx.pid;
error_log $work/nginx/error.log;
events { worker_connections 64; }
http {
  access_log $work/nginx/access.log;
  client_body_temp_path $work/nginx/body;
  proxy_temp_path $work/nginx/proxy;
  fastcgi_temp_path $work/nginx/fastcgi;
  uwsgi_temp_path $work/nginx/uwsgi;
  scgi_temp_path $work/nginx/scgi;
  server {
    listen 127.0.0.1:$1;
    root $work/dav;
    location /cache/ { dav_methods PUT DELETE; create_full_put_path on; client_max_body_size 64m; }
  }
  $tls
}
CONF
  nginx -c "$work/nginx.conf" -p "$work/nginx" > "$work/nginx/stdout.log" 2>&1 &
  pids+=($!)
  wait_port "$1"
  [ -z "${2:-}" ] || wait_port "$2"
}

new_tree() {  # new_tree NAME: a copy of examples/bloom with a build folder of its own
  mkdir -p "$work/$1/src" "$work/$1/build"
  cp "$root/examples/bloom/Bloom.h" "$root/examples/bloom/Bloom.cpp" "$work/$1/src/"
}
# translate TREE STORAGE [crossrt options...]: what crossrt_add_class runs, with a remote storage
translate() {
  local t=$work/$1 storage=$2; shift 2
  timeout 120 "$crossrt" translate --class Bloom --backend vulkan --out "$t/build/gen" --source "$t/src/Bloom.cpp" \
    --templates "$root/templates" --depfile "$t/build/gen/Bloom.d" --depfile-target "$t/build/gen/Bloom_Vulkan.h" \
    --build-dir "$t/build" --source-root "$t/src" --remote-storage "$storage" "$@" \
    -- -std=c++17 -I"$root/libs/litemath" -I"$t/src"
}
translations() {  # how many translations the tree's daemon ran (none when it never started)
  if [ -f "$work/$1/build/crossrtd.log" ]; then grep -c "translate Bloom" "$work/$1/build/crossrtd.log" || true; else echo 0; fi
}
# same_as_local TREE: the tree's generated files are byte-identical to a local translation there
same_as_local() {
  local t=$work/$1
  rm -rf "$t/build/fetched" && mv "$t/build/gen" "$t/build/fetched"
  translate "$1" "" --no-daemon > /dev/null 2>&1 || fail "$1: the local translation failed"
  diff -r -x .crossrt-manifest.json "$t/build/gen" "$t/build/fetched" > "$work/diff.txt" || { head -20 "$work/diff.txt"; fail "$1: fetched files differ from a local translation"; }
}
