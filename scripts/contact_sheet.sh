#!/usr/bin/env bash
# Contact sheet: every glTF model under a folder rendered with one environment, 8 to a row, in
# alphabetical order (docs/measurements/environment.md).
# Usage: bash scripts/contact_sheet.sh ENVIRONMENT OUT.png [MODELS_DIR] [WHITTED]
#   MODELS_DIR defaults to ../shared/assets/gltf beside the repo, WHITTED to build/release/apps/whitted.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
ENV="$1" OUT="$2" MODELS="${3:-$ROOT/../shared/assets/gltf}" WHITTED="${4:-$ROOT/build/release/apps/whitted}"
TMP="$(mktemp -d)"
trap 'rm -rf "$TMP"' EXIT
tiles=()
for d in "$MODELS"/*/; do
  m="$(basename "$d")"
  f="$(find "$d" -name '*.glb' | sort | head -1)"
  [ -z "$f" ] && f="$(find "$d" -name '*.gltf' | grep -v -e Draco -e Embedded -e Meshopt -e Quantized | sort | head -1)"
  [ -z "$f" ] && continue
  if "$WHITTED" render "$f" -o "$TMP/$m.png" --environment "$ENV" --width 200 --height 150 --no-progress \
       --log-level error >/dev/null 2>"$TMP/$m.err"; then
    tiles+=("$TMP/$m.png")
  else
    echo "contact_sheet: $m: $(head -1 "$TMP/$m.err")" >&2
  fi
done
oiiotool "${tiles[@]}" --mosaic "8x$(( (${#tiles[@]} + 7) / 8 ))" -o "$OUT"
echo "contact_sheet: ${#tiles[@]} models -> $OUT" >&2
