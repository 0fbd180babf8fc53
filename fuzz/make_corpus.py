#!/usr/bin/env python3
"""Builds the seed corpora of the fuzz harnesses from the repository's files (docs/fuzzing.md).

    python3 fuzz/make_corpus.py OUT_DIR [--max-size BYTES]

writes OUT_DIR/gltf (JSON glTF with every external buffer and image inlined as a data: URI, so a
harness that never reads the file system still sees the whole file), OUT_DIR/glb (the repo's
small .glb files, plus a GLB made from each inlined glTF with buffer 0 as the BIN chunk) and
OUT_DIR/image (PNG and JPEG files, and the images embedded in .glb files) and OUT_DIR/scene
(the JSON scene files: assets/scenes/*.json and the fixtures of tests/data/scene-files). Sources: assets/ and
tests/data/ (the broken files of tests/data/gltf-invalid and tests/data/fuzz-regressions).
Deterministic: the same tree gives the same corpus; files above --max-size are left out.
"""
import argparse
import base64
import hashlib
import json
import pathlib
import struct

ROOT = pathlib.Path(__file__).resolve().parent.parent
SOURCES = [ROOT / "assets", ROOT / "tests" / "data"]
MIME = {".png": "image/png", ".jpg": "image/jpeg", ".jpeg": "image/jpeg", ".bin": "application/octet-stream"}


def files(suffixes):
    for src in SOURCES:
        for p in sorted(src.rglob("*")):
            if p.is_file() and p.suffix.lower() in suffixes:
                yield p


def write(out_dir, data, max_size):
    if 0 < len(data) <= max_size:
        out_dir.mkdir(parents=True, exist_ok=True)
        (out_dir / hashlib.sha1(data).hexdigest()).write_bytes(data)


def inline(path):
    """The glTF at `path` with external buffers/images replaced by data: URIs; None if unreadable."""
    try:
        doc = json.loads(path.read_bytes())
    except (ValueError, UnicodeDecodeError, RecursionError):
        return None
    if not isinstance(doc, dict):
        return None
    for key in ("buffers", "images"):
        for item in doc.get(key, []) if isinstance(doc.get(key), list) else []:
            uri = item.get("uri") if isinstance(item, dict) else None
            if not isinstance(uri, str) or uri.startswith("data:"):
                continue
            target = path.parent / uri
            if target.is_file() and target.stat().st_size <= 1 << 20:
                mime = MIME.get(target.suffix.lower(), "application/octet-stream")
                item["uri"] = f"data:{mime};base64," + base64.b64encode(target.read_bytes()).decode()
    return doc


def to_glb(doc):
    """A GLB with buffer 0 (when it is a data: URI) moved into the BIN chunk."""
    bin_chunk = b""
    buffers = doc.get("buffers")
    if isinstance(buffers, list) and buffers and isinstance(buffers[0], dict):
        uri = buffers[0].get("uri", "")
        if isinstance(uri, str) and uri.startswith("data:") and ";base64," in uri:
            try:
                bin_chunk = base64.b64decode(uri.split(";base64,", 1)[1])
                del buffers[0]["uri"]
            except ValueError:
                bin_chunk = b""
    js = json.dumps(doc, separators=(",", ":")).encode()
    js += b" " * (-len(js) % 4)
    bin_chunk += b"\0" * (-len(bin_chunk) % 4)
    body = struct.pack("<I4s", len(js), b"JSON") + js
    if bin_chunk:
        body += struct.pack("<I4s", len(bin_chunk), b"BIN\0") + bin_chunk
    return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body


def glb_images(data):
    """Encoded images stored in a GLB's bufferViews."""
    try:
        magic, _, _ = struct.unpack_from("<4sII", data, 0)
        jlen, _ = struct.unpack_from("<I4s", data, 12)
        doc = json.loads(data[20:20 + jlen])
        blen, _ = struct.unpack_from("<I4s", data, 20 + jlen)
        bin_chunk = data[28 + jlen:28 + jlen + blen]
    except (struct.error, ValueError, UnicodeDecodeError, RecursionError):
        return
    if magic != b"glTF":
        return
    for img in doc.get("images", []):
        view = img.get("bufferView")
        if isinstance(view, int) and 0 <= view < len(doc.get("bufferViews", [])):
            bv = doc["bufferViews"][view]
            off = bv.get("byteOffset", 0)
            yield bin_chunk[off:off + bv.get("byteLength", 0)]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out_dir", type=pathlib.Path)
    ap.add_argument("--max-size", type=int, default=65536, help="largest seed kept, bytes (default 65536)")
    args = ap.parse_args()
    out, cap = args.out_dir, args.max_size

    for p in files({".gltf"}):
        write(out / "gltf", p.read_bytes(), cap)  # as is (broken files stay broken)
        doc = inline(p)
        if doc is not None:
            write(out / "gltf", json.dumps(doc, separators=(",", ":")).encode(), cap)
            write(out / "glb", to_glb(doc), cap)
    for p in files({".glb"}):
        data = p.read_bytes()
        write(out / "glb", data, cap)
        for img in glb_images(data):
            write(out / "image", img, cap)
    for p in files({".png", ".jpg", ".jpeg"}):
        write(out / "image", p.read_bytes(), cap)
    # Scene files: the bundled scenes and the test fixtures (JSON, read as they are).
    for p in files({".json"}):
        if p.name.endswith(".schema.json"):
            continue
        write(out / "scene", p.read_bytes(), cap)
    # tests/data/fuzz-regressions/<harness>/... go to that harness's corpus as they are.
    reg = ROOT / "tests" / "data" / "fuzz-regressions"
    for harness in ("gltf", "glb", "image", "scene"):
        for p in sorted((reg / harness).glob("*")) if (reg / harness).is_dir() else []:
            if p.is_file() and p.suffix != ".md":
                write(out / harness, p.read_bytes(), 1 << 30)
    for harness in ("gltf", "glb", "image", "scene"):
        n = len(list((out / harness).glob("*"))) if (out / harness).is_dir() else 0
        print(f"make_corpus: {harness}: {n} seeds")


if __name__ == "__main__":
    main()
