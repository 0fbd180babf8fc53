#!/usr/bin/env python3
"""Two glTF scenes for measuring instancing against flattening (docs/measurements/performance.md,
"Instances against one flat structure"): `rings_own.gltf`, N interlocking tori each with its own
mesh (a node each, rotated and placed in a small box: their bounds overlap heavily), and
`rings_shared.gltf`, the same N nodes all using one mesh (heavy reuse). Deterministic (seeded).

    python3 scripts/make_instancing_scenes.py OUT_DIR [--rings 400] [--segments 24]
"""
import argparse
import base64
import json
import math
import os
import random
import struct


def torus(segments, sides, R=1.0, r=0.12):
    pos, idx = [], []
    for i in range(segments):
        a = 2 * math.pi * i / segments
        for j in range(sides):
            b = 2 * math.pi * j / sides
            pos.append(((R + r * math.cos(b)) * math.cos(a), r * math.sin(b), (R + r * math.cos(b)) * math.sin(a)))
    for i in range(segments):
        for j in range(sides):
            a, b = i * sides + j, ((i + 1) % segments) * sides + j
            c, d = ((i + 1) % segments) * sides + (j + 1) % sides, i * sides + (j + 1) % sides
            idx += [a, b, c, a, c, d]
    return pos, idx


def quat(rng):
    u1, u2, u3 = rng.random(), rng.random(), rng.random()
    return [math.sqrt(1 - u1) * math.sin(2 * math.pi * u2), math.sqrt(1 - u1) * math.cos(2 * math.pi * u2),
            math.sqrt(u1) * math.sin(2 * math.pi * u3), math.sqrt(u1) * math.cos(2 * math.pi * u3)]


def write(path, rings, segments, shared):
    rng = random.Random(7)
    pos, idx = torus(segments, max(6, segments // 3))
    blob = b"".join(struct.pack("<3f", *p) for p in pos)
    idx_bytes = b"".join(struct.pack("<I", i) for i in idx)
    lo = [min(p[k] for p in pos) for k in range(3)]
    hi = [max(p[k] for p in pos) for k in range(3)]
    meshes, accessors, views, nodes = [], [], [], []
    buffer = b""
    copies = 1 if shared else rings
    for m in range(copies):
        views.append({"buffer": 0, "byteOffset": len(buffer), "byteLength": len(blob), "target": 34962})
        buffer += blob
        views.append({"buffer": 0, "byteOffset": len(buffer), "byteLength": len(idx_bytes), "target": 34963})
        buffer += idx_bytes
        accessors.append({"bufferView": 2 * m, "componentType": 5126, "count": len(pos), "type": "VEC3", "min": lo, "max": hi})
        accessors.append({"bufferView": 2 * m + 1, "componentType": 5125, "count": len(idx), "type": "SCALAR"})
        meshes.append({"primitives": [{"attributes": {"POSITION": 2 * m}, "indices": 2 * m + 1, "material": 0}]})
    side = (rings ** (1.0 / 3.0)) * 0.9  # ~1 ring per 0.7 units^3: they interlock
    for n in range(rings):
        nodes.append({"mesh": 0 if shared else n, "rotation": quat(rng),
                      "translation": [rng.uniform(-side, side) for _ in range(3)]})
    doc = {
        "asset": {"version": "2.0", "generator": "whitted scripts/make_instancing_scenes.py"},
        "scene": 0, "scenes": [{"nodes": list(range(rings))}], "nodes": nodes, "meshes": meshes,
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.6, 0.3, 1], "metallicFactor": 0.0,
                                                "roughnessFactor": 0.6}}],
        "accessors": accessors, "bufferViews": views,
        "buffers": [{"byteLength": len(buffer),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(buffer).decode()}],
    }
    with open(path, "w") as f:
        json.dump(doc, f)
    return len(idx) // 3 * rings


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--rings", type=int, default=400)
    ap.add_argument("--segments", type=int, default=24)
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    for name, shared in (("rings_own.gltf", False), ("rings_shared.gltf", True)):
        tris = write(os.path.join(a.out, name), a.rings, a.segments, shared)
        print(f"{os.path.join(a.out, name)}: {a.rings} nodes, {tris} triangles")


if __name__ == "__main__":
    main()
