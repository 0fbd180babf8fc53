#!/usr/bin/env bash
# Re-makes the bundled compressed glTF variants (docs/measurements/compressed-gltf.md) with glTF
# Transform and its encoders, installed from the npm registry into a temporary directory at the
# pinned versions. Not part of the build or the tests: its outputs are committed in assets/.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
cp "$ROOT/scripts/make_compressed_assets.mjs" "$WORK/"
(cd "$WORK" && npm init -y >/dev/null && npm install --no-audit --no-fund --silent \
  @gltf-transform/core@4.5.1 @gltf-transform/extensions@4.5.1 @gltf-transform/functions@4.5.1 \
  meshoptimizer@1.3.0 draco3dgltf@1.5.7 sharp@0.34.5)
A="$ROOT/assets/gltf"
make() { node "$WORK/make_compressed_assets.mjs" "$A/$1/glTF-Binary/$1.glb" "$2" "$A/$1/glTF-$2/$1.glb"; }
make Box Draco
make Box Meshopt
make Duck Draco
make Duck MeshoptFiltered
make Duck WebP
