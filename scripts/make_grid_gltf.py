#!/usr/bin/env python3
"""Writes grid.glb: the height-field grid of make_compressed_assets.mjs (grid:N) without npm.

One mesh of 2*N*N triangles over (N+1)^2 vertices with normals and TEXCOORD_0, uint32 indices,
the default material. N = 708 gives the 1,002,528-triangle mesh of the memory measurements
(docs/measurements/performance.md).
    python3 scripts/make_grid_gltf.py 708 /tmp/large/grid.glb
"""
import json
import math
import struct
import sys
from array import array


def main():
    n, out = int(sys.argv[1]), sys.argv[2]
    v = n + 1
    pos, nor, uv = array("f"), array("f"), array("f")
    for j in range(v):
        for i in range(v):
            x, z = i / n - 0.5, j / n - 0.5
            pos.extend([x, 0.05 * math.sin(9 * x) * math.cos(7 * z), z])
            dx = 0.45 * math.cos(9 * x) * math.cos(7 * z)
            dz = -0.35 * math.sin(9 * x) * math.sin(7 * z)
            length = math.hypot(dx, 1, dz)
            nor.extend([-dx / length, 1 / length, -dz / length])
            uv.extend([i / n, j / n])
    idx = array("I")
    for j in range(n):
        for i in range(n):
            a = j * v + i
            idx.extend([a, a + v, a + 1, a + 1, a + v, a + v + 1])
    assert idx.itemsize == 4 and pos.itemsize == 4
    if sys.byteorder != "little":
        for a in (pos, nor, uv, idx):
            a.byteswap()
    blobs = [idx.tobytes(), pos.tobytes(), nor.tobytes(), uv.tobytes()]
    views, offset = [], 0
    for b in blobs:
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(b)})
        offset += len(b)
    gltf = {
        "asset": {"version": "2.0", "generator": "scripts/make_grid_gltf.py"},
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 1, "NORMAL": 2, "TEXCOORD_0": 3},
                                    "indices": 0, "material": 0}]}],
        "materials": [{}],
        "accessors": [
            {"bufferView": 0, "componentType": 5125, "count": len(idx), "type": "SCALAR"},
            {"bufferView": 1, "componentType": 5126, "count": v * v, "type": "VEC3",
             "min": [min(pos[k::3]) for k in range(3)], "max": [max(pos[k::3]) for k in range(3)]},
            {"bufferView": 2, "componentType": 5126, "count": v * v, "type": "VEC3"},
            {"bufferView": 3, "componentType": 5126, "count": v * v, "type": "VEC2"},
        ],
        "bufferViews": views, "buffers": [{"byteLength": offset}],
    }
    js = json.dumps(gltf).encode()
    js += b" " * (-len(js) % 4)
    binary = b"".join(blobs)
    with open(out, "wb") as f:
        f.write(struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(js) + 8 + len(binary)))
        f.write(struct.pack("<II", len(js), 0x4E4F534A) + js)
        f.write(struct.pack("<II", len(binary), 0x004E4942) + binary)


if __name__ == "__main__":
    main()
