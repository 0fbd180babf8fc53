#!/usr/bin/env bash
# Re-makes the bundled compressed glTF variants (docs/measurements/compressed-gltf.md) with glTF
# Transform and its encoders, installed from the npm registry into a temporary directory at the
# pinned versions. Not part of the build or the tests: its outputs are committed in assets/.
#   bash scripts/make_compressed_assets.sh              the bundled variants, into assets/gltf/
#   bash scripts/make_compressed_assets.sh --large DIR  Draco and meshopt variants of the
#       1M-triangle MetalRoughSpheresNoTextures (instanced spheres) and of a generated single
#       mesh of 1,002,528 triangles (grid.glb) into DIR; not bundled: the load-time table in
#       docs/measurements/compressed-gltf.md
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
LARGE=""
if [ "${1:-}" = "--large" ]; then
  LARGE="${2:?usage: make_compressed_assets.sh [--large DIR]}"
  mkdir -p "$LARGE"
  LARGE="$(cd "$LARGE" && pwd)"
fi
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
cp "$ROOT/scripts/make_compressed_assets.mjs" "$WORK/"
(cd "$WORK" && npm init -y >/dev/null && npm install --no-audit --no-fund --silent \
  @gltf-transform/core@4.5.1 @gltf-transform/extensions@4.5.1 @gltf-transform/functions@4.5.1 \
  meshoptimizer@1.3.0 draco3dgltf@1.5.7 sharp@0.34.5)
A="$ROOT/assets/gltf"
if [ -n "$LARGE" ]; then
  M=MetalRoughSpheresNoTextures
  cp "$A/$M/glTF-Binary/$M.glb" "$LARGE/$M.glb"
  node "$WORK/make_compressed_assets.mjs" grid:708 Plain "$LARGE/grid.glb"
  for v in Draco Meshopt MeshoptFiltered; do
    node "$WORK/make_compressed_assets.mjs" "$A/$M/glTF-Binary/$M.glb" "$v" "$LARGE/$M-$v.glb"
    node "$WORK/make_compressed_assets.mjs" "$LARGE/grid.glb" "$v" "$LARGE/grid-$v.glb"
  done
  ls -l "$LARGE"
  exit 0
fi
make() { node "$WORK/make_compressed_assets.mjs" "$A/$1/glTF-Binary/$1.glb" "$2" "$A/$1/glTF-$2/$1.glb"; }
make Box Draco
make Box Meshopt
make Duck Draco
make Duck MeshoptFiltered
make Duck WebP
