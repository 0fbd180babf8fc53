#!/usr/bin/env python3
"""Loading scales linearly (issue: costs that grow with the scene), checked without timing anything.

Counts the instructions a whole `whitted info` process executes (valgrind's cachegrind without
its cache simulation: a count, the same from run to run up to start-up noise of about 1e-4) for
an empty scene and for n and 4n objects, and compares the marginal instructions per object: a
linear loader costs the same per object at both sizes; a quadratic one (like the JSON builder
this replaced, which scanned /objects at the end of every element) costs about 4 times as much
per object between n and 4n. Two generated inputs: a scene file of spheres and a glTF file of nodes, each
with its own small mesh. Usage: test_load_scaling.py WHITTED_EXE
"""
import json
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile

# Marginal cost per object from n to 4n over the cost per object up to n: linear ~1; quadratic
# ~5 (less where a linear part dominates: the replaced JSON builder measured 1.78 here).
LIMIT = 1.3


def sphere_file(path, n):
    objs = ['{"type": "sphere", "center": [%d, %d, %d], "radius": 0.4, "material": "m%d"}'
            % (i % 20, (i // 20) % 20, i // 400, i % 3) for i in range(n)]
    with open(path, "w") as f:
        f.write('{"version": 1, "materials": {"m0": {"kd": [0.8, 0.2, 0.2]}, "m1": {"kd": 0.5}, '
                '"m2": {"kd": 0.5, "kr": 0.3}},\n"objects": [\n' + ",\n".join(objs) + "]}\n")


def node_file(path, n):
    """n nodes, each with its own mesh (a tetrahedron: own accessors and bufferViews)."""
    n = max(n, 1)
    vb = b"".join(struct.pack("<3f", *p) for p in [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)])
    ib = struct.pack("<12H", 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3)
    views, accessors, meshes, nodes = [], [], [], []
    for i in range(n):
        views += [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 24}]
        accessors += [{"bufferView": 2 * i, "componentType": 5126, "count": 4, "type": "VEC3",
                       "min": [0, 0, 0], "max": [1, 1, 1]},
                      {"bufferView": 2 * i + 1, "componentType": 5123, "count": 12, "type": "SCALAR"}]
        meshes.append({"primitives": [{"attributes": {"POSITION": 2 * i}, "indices": 2 * i + 1}]})
        nodes.append({"mesh": i, "translation": [2 * (i % 100), 2 * (i // 100), 0]})
    with open(path + ".bin", "wb") as f:
        f.write(vb + ib)
    doc = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": list(range(n))}], "nodes": nodes,
           "meshes": meshes, "accessors": accessors, "bufferViews": views,
           "buffers": [{"byteLength": 72, "uri": os.path.basename(path) + ".bin"}]}
    with open(path, "w") as f:
        json.dump(doc, f)


def instructions(exe, path):
    # whitted's huge-page restart (src/core/huge_pages.h) is skipped under valgrind; the
    # variable says so explicitly, so the count is of one process either way.
    env = dict(os.environ, WHITTED_HUGE_PAGES="0")
    r = subprocess.run(["valgrind", "--tool=cachegrind", "--cache-sim=no", "--cachegrind-out-file=/dev/null",
                        exe, "info", "--no-environment", "--no-textures", path],
                       stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, check=False, env=env)
    m = re.search(r"I\s+refs:\s+([\d,]+)", r.stderr)
    if r.returncode != 0 or not m:
        sys.exit(f"test_load_scaling: valgrind/whitted info failed on {path} (exit {r.returncode}):\n{r.stderr[-2000:]}")
    return int(m.group(1).replace(",", ""))


def main():
    exe = sys.argv[1]
    if shutil.which("valgrind") is None:
        sys.exit("test_load_scaling: valgrind is not installed (scripts/dev installs it)")
    work = tempfile.mkdtemp(prefix="whitted_scaling_")
    failed = False
    try:
        for what, make, ext, n in (("scene-file spheres", sphere_file, "json", 4000),
                                   ("glTF nodes with own meshes", node_file, "gltf", 500)):
            counts = {}
            for size in (0, n, 4 * n):
                path = os.path.join(work, f"{size}.{ext}")
                make(path, size)
                counts[size] = instructions(exe, path)
            base = counts[0]
            small = (counts[n] - base) / n
            large = (counts[4 * n] - counts[n]) / (3 * n)
            ratio = large / small
            ok = small > 0 and ratio < LIMIT
            failed |= not ok
            print(f"{what}: {base:,} instructions empty; {small:,.0f} per object up to {n}, {large:,.0f} from {n} to {4 * n}: "
                  f"ratio {ratio:.3f} (linear ~1, limit {LIMIT}) {'ok' if ok else 'FAILED: not linear'}")
    finally:
        shutil.rmtree(work, ignore_errors=True)
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
