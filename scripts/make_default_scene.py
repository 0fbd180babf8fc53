#!/usr/bin/env python3
"""Build assets/scenes/default.glb, the scene the README's first command renders.

A table-top still life at real-world scale (metres, +Y up) that shows what a Whitted (1980)
ray tracer does: a mirror sphere, a refracting glass sphere and glass hurricane (refraction
through KHR_materials_volume), a red thin transparent panel whose shadow is tinted, a textured
duck, and three punctual lights (so every object casts several shadows), inside a small room
so that mirror and glass always have something to show.

Real assets are read from assets/gltf/<Model>/ (see assets/scenes/README.md for credits) and
merged into one glTF: their buffers, images and every index (bufferView, accessor, mesh,
material, texture, image, sampler, node) are rebased, and each asset becomes one node subtree
with a transform chosen here. Generated meshes (floor, walls, spheres, panel) and a generated
checkerboard PNG are added, with lights and one camera, and everything is written as one
GLB 2.0 file. Python 3.11 standard library only; the output is byte-for-byte deterministic.

Usage:  python3 scripts/make_default_scene.py [--out assets/scenes/default.glb]
"""

import argparse
import base64
import json
import math
import os
import struct
import zlib

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# glTF constants
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963
FLOAT, UNSIGNED_SHORT, UNSIGNED_INT = 5126, 5123, 5125
LINEAR, REPEAT = 9729, 10497


def rnd(x, digits=6):
    """Round for a tidy, stable JSON text (and -0.0 -> 0.0)."""
    v = round(float(x), digits)
    return 0.0 if v == 0 else v


def rnd_list(values, digits=6):
    return [rnd(v, digits) for v in values]


# ---------------------------------------------------------------------------------------------
# Small vector / quaternion helpers
# ---------------------------------------------------------------------------------------------

def sub(a, b):
    return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def normalize(a):
    n = math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])
    return [a[0] / n, a[1] / n, a[2] / n]


def quat_from_basis(x, y, z):
    """Unit quaternion (x, y, z, w) of the rotation whose matrix columns are x, y, z."""
    m00, m01, m02 = x[0], y[0], z[0]
    m10, m11, m12 = x[1], y[1], z[1]
    m20, m21, m22 = x[2], y[2], z[2]
    tr = m00 + m11 + m22
    if tr > 0:
        s = math.sqrt(tr + 1.0) * 2
        q = [(m21 - m12) / s, (m02 - m20) / s, (m10 - m01) / s, 0.25 * s]
    elif m00 > m11 and m00 > m22:
        s = math.sqrt(1.0 + m00 - m11 - m22) * 2
        q = [0.25 * s, (m01 + m10) / s, (m02 + m20) / s, (m21 - m12) / s]
    elif m11 > m22:
        s = math.sqrt(1.0 + m11 - m00 - m22) * 2
        q = [(m01 + m10) / s, 0.25 * s, (m12 + m21) / s, (m02 - m20) / s]
    else:
        s = math.sqrt(1.0 + m22 - m00 - m11) * 2
        q = [(m02 + m20) / s, (m12 + m21) / s, 0.25 * s, (m10 - m01) / s]
    n = math.sqrt(sum(c * c for c in q))
    q = [c / n for c in q]
    if q[3] < 0:  # canonical sign
        q = [-c for c in q]
    return q


def look_at_quat(eye, target, up=(0.0, 1.0, 0.0)):
    """Rotation that points a node's -Z axis (cameras, spot and directional lights) at target."""
    back = normalize(sub(eye, target))  # node +Z
    right = normalize(cross(list(up), back))
    true_up = cross(back, right)
    return quat_from_basis(right, true_up, back)


def quat_axis_angle(axis, degrees):
    axis = normalize(list(axis))
    h = math.radians(degrees) / 2
    s = math.sin(h)
    return [axis[0] * s, axis[1] * s, axis[2] * s, math.cos(h)]


# ---------------------------------------------------------------------------------------------
# GLB reading and the merged document
# ---------------------------------------------------------------------------------------------

def read_gltf(path):
    """Returns (json dict, list of buffer bytes) for a .glb or .gltf (external or data URIs)."""
    base = os.path.dirname(path)
    with open(path, "rb") as f:
        data = f.read()
    bin_chunk = None
    if data[:4] == b"glTF":
        offset = 12
        doc = None
        while offset < len(data):
            length, ctype = struct.unpack_from("<II", data, offset)
            chunk = data[offset + 8: offset + 8 + length]
            if ctype == 0x4E4F534A:
                doc = json.loads(chunk.decode("utf-8"))
            elif ctype == 0x004E4942:
                bin_chunk = chunk
            offset += 8 + length
    else:
        doc = json.loads(data.decode("utf-8"))

    def load_uri(uri):
        if uri.startswith("data:"):
            return base64.b64decode(uri.split(",", 1)[1])
        with open(os.path.join(base, uri), "rb") as f:
            return f.read()

    buffers = []
    for b in doc.get("buffers", []):
        buffers.append(load_uri(b["uri"]) if "uri" in b else bin_chunk)
    # Images given by URI become plain bytes; merge() embeds them into the BIN chunk.
    for img in doc.get("images", []):
        if "uri" in img:
            img["_bytes"] = load_uri(img.pop("uri"))
            if "mimeType" not in img:
                img["mimeType"] = "image/png" if img["_bytes"][:4] == b"\x89PNG" else "image/jpeg"
    return doc, buffers


class Document:
    """The glTF being built: JSON arrays plus one growing binary buffer."""

    def __init__(self):
        self.j = {
            "asset": {"version": "2.0", "generator": "whitted scripts/make_default_scene.py"},
            "extensionsUsed": [],
            "scene": 0,
            "scenes": [{"name": "default", "nodes": []}],
            "nodes": [], "cameras": [], "meshes": [], "materials": [], "textures": [],
            "images": [], "samplers": [], "accessors": [], "bufferViews": [],
            "buffers": [{"byteLength": 0}],
        }
        self.bin = bytearray()
        self.lights = []

    def use_extension(self, name, required=False):
        if name not in self.j["extensionsUsed"]:
            self.j["extensionsUsed"].append(name)
        if required:
            req = self.j.setdefault("extensionsRequired", [])
            if name not in req:
                req.append(name)

    def add_view(self, data, target=None):
        """Appends bytes (4-byte aligned) as a bufferView; returns its index."""
        while len(self.bin) % 4:
            self.bin.append(0)
        view = {"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data)}
        if target is not None:
            view["target"] = target
        self.bin += data
        self.j["bufferViews"].append(view)
        return len(self.j["bufferViews"]) - 1

    def add_accessor(self, values, ctype, atype, target, minmax=False):
        """Packs a flat list as a tightly packed accessor with its own bufferView."""
        fmt = {FLOAT: "f", UNSIGNED_SHORT: "H", UNSIGNED_INT: "I"}[ctype]
        ncomp = {"SCALAR": 1, "VEC2": 2, "VEC3": 3}[atype]
        data = struct.pack("<%d%s" % (len(values), fmt), *values)
        acc = {"bufferView": self.add_view(data, target), "componentType": ctype,
               "count": len(values) // ncomp, "type": atype}
        if minmax:
            cols = [values[i::ncomp] for i in range(ncomp)]
            # min/max of the float32 values actually stored
            if ctype == FLOAT:
                cols = [[struct.unpack("<f", struct.pack("<f", v))[0] for v in c] for c in cols]
            acc["min"] = [min(c) for c in cols]
            acc["max"] = [max(c) for c in cols]
        self.j["accessors"].append(acc)
        return len(self.j["accessors"]) - 1

    def add_node(self, node, parent=None):
        self.j["nodes"].append(node)
        idx = len(self.j["nodes"]) - 1
        if parent is None:
            self.j["scenes"][0]["nodes"].append(idx)
        else:
            self.j["nodes"][parent].setdefault("children", []).append(idx)
        return idx

    def add_material(self, mat):
        self.j["materials"].append(mat)
        return len(self.j["materials"]) - 1

    def add_mesh(self, name, positions, normals, uvs, indices, material):
        prim = {
            "attributes": {
                "POSITION": self.add_accessor(positions, FLOAT, "VEC3", ARRAY_BUFFER, minmax=True),
                "NORMAL": self.add_accessor(normals, FLOAT, "VEC3", ARRAY_BUFFER),
                "TEXCOORD_0": self.add_accessor(uvs, FLOAT, "VEC2", ARRAY_BUFFER),
            },
            "indices": self.add_accessor(
                indices, UNSIGNED_SHORT if len(positions) // 3 < 65536 else UNSIGNED_INT,
                "SCALAR", ELEMENT_ARRAY_BUFFER, minmax=False),
            "material": material,
        }
        self.j["meshes"].append({"name": name, "primitives": [prim]})
        return len(self.j["meshes"]) - 1

    def add_png_texture(self, png, name):
        self.j["samplers"].append({"magFilter": LINEAR, "minFilter": LINEAR, "wrapS": REPEAT, "wrapT": REPEAT})
        self.j["images"].append({"name": name, "bufferView": self.add_view(png), "mimeType": "image/png"})
        self.j["textures"].append({"sampler": len(self.j["samplers"]) - 1, "source": len(self.j["images"]) - 1})
        return len(self.j["textures"]) - 1

    def add_light(self, light, name, translation, rotation=None):
        self.use_extension("KHR_lights_punctual")
        light = dict(light, name=name)
        self.lights.append(light)
        node = {"name": name, "translation": rnd_list(translation)}
        if rotation is not None:
            node["rotation"] = rnd_list(rotation, 7)
        node["extensions"] = {"KHR_lights_punctual": {"light": len(self.lights) - 1}}
        return self.add_node(node)

    # -- merging a whole asset --------------------------------------------------------------

    def merge(self, path, name, translation, rotation, scale):
        """Imports every node of the asset's default scene under a new root node; returns it."""
        src, buffers = read_gltf(path)
        j = self.j
        # bufferViews: copy each view's bytes into our BIN chunk (keeping stride and target)
        view_base = len(j["bufferViews"])
        for v in src.get("bufferViews", []):
            blob = buffers[v["buffer"]]
            start = v.get("byteOffset", 0)
            new = self.add_view(blob[start:start + v["byteLength"]], v.get("target"))
            if "byteStride" in v:
                j["bufferViews"][new]["byteStride"] = v["byteStride"]
            if "name" in v:
                j["bufferViews"][new]["name"] = v["name"]
        acc_base = len(j["accessors"])
        for a in src.get("accessors", []):
            a = json.loads(json.dumps(a))
            if "bufferView" in a:
                a["bufferView"] += view_base
            if "sparse" in a:
                a["sparse"]["indices"]["bufferView"] += view_base
                a["sparse"]["values"]["bufferView"] += view_base
            j["accessors"].append(a)
        img_base = len(j["images"])
        for img in src.get("images", []):
            if "_bytes" in img:
                data = img.pop("_bytes")
                img["bufferView"] = self.add_view(data)
            else:
                img["bufferView"] += view_base
            j["images"].append(img)
        samp_base = len(j["samplers"])
        j["samplers"] += src.get("samplers", [])
        tex_base = len(j["textures"])
        for t in src.get("textures", []):
            t = dict(t)
            if "source" in t:
                t["source"] += img_base
            if "sampler" in t:
                t["sampler"] += samp_base
            j["textures"].append(t)

        def rebase_textures(obj):
            # every textureInfo ({"index": ...} under a key ending in "Texture"), extensions included
            if isinstance(obj, dict):
                for k, v in obj.items():
                    if k.endswith("Texture") and isinstance(v, dict) and "index" in v:
                        v["index"] += tex_base
                    rebase_textures(v)
            elif isinstance(obj, list):
                for v in obj:
                    rebase_textures(v)

        mat_base = len(j["materials"])
        for m in src.get("materials", []):
            rebase_textures(m)
            j["materials"].append(m)
        mesh_base = len(j["meshes"])
        for mesh in src.get("meshes", []):
            for p in mesh["primitives"]:
                p["attributes"] = {k: v + acc_base for k, v in p["attributes"].items()}
                if "indices" in p:
                    p["indices"] += acc_base
                if "material" in p:
                    p["material"] += mat_base
                for t in p.get("targets", []):
                    for k in t:
                        t[k] += acc_base
            j["meshes"].append(mesh)
        for ext in src.get("extensionsUsed", []):
            self.use_extension(ext)
        for ext in src.get("extensionsRequired", []):
            self.use_extension(ext, required=True)

        # Nodes: cameras, skins and animations of the assets are dropped (the scene's camera
        # is ours); everything else is rebased.
        root = self.add_node({"name": name, "translation": rnd_list(translation),
                              "rotation": rnd_list(rotation, 7), "scale": rnd_list(scale)})
        src_nodes = [dict(n) for n in src.get("nodes", [])]
        for n in src_nodes:
            n.pop("skin", None)
            if n.pop("camera", None) is not None and "mesh" not in n and not n.get("children"):
                n["_drop"] = True  # a camera-only leaf would be left empty
        remap, next_index = {}, len(j["nodes"])
        for i, n in enumerate(src_nodes):
            if not n.get("_drop"):
                remap[i] = next_index
                next_index += 1
        for i, n in enumerate(src_nodes):
            if n.get("_drop"):
                continue
            if "mesh" in n:
                n["mesh"] += mesh_base
            if "children" in n:
                n["children"] = [remap[c] for c in n["children"] if c in remap]
            j["nodes"].append(n)
        scene = src["scenes"][src.get("scene", 0)]
        j["nodes"][root]["children"] = [remap[c] for c in scene["nodes"] if c in remap]
        return root

    def write_glb(self, path):
        j = self.j
        if self.lights:
            j["extensions"] = {"KHR_lights_punctual": {"lights": self.lights}}
        for key in ("cameras", "textures", "images", "samplers", "extensionsUsed"):
            if not j.get(key):
                j.pop(key, None)
        while len(self.bin) % 4:
            self.bin.append(0)
        j["buffers"][0]["byteLength"] = len(self.bin)
        text = json.dumps(j, separators=(",", ":"), ensure_ascii=True).encode("ascii")
        text += b" " * ((4 - len(text) % 4) % 4)
        total = 12 + 8 + len(text) + 8 + len(self.bin)
        out = bytearray()
        out += struct.pack("<III", 0x46546C67, 2, total)
        out += struct.pack("<II", len(text), 0x4E4F534A) + text
        out += struct.pack("<II", len(self.bin), 0x004E4942) + self.bin
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "wb") as f:
            f.write(out)
        return len(out)


# ---------------------------------------------------------------------------------------------
# Generated geometry and texture
# ---------------------------------------------------------------------------------------------

def quad(center, u_axis, v_axis, half_u, half_v, uv_scale=(1.0, 1.0)):
    """Rectangle center +- half_u*u_axis +- half_v*v_axis; front face (CCW) along u x v."""
    n = normalize(cross(u_axis, v_axis))
    pos, nor, uv = [], [], []
    for su, sv in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
        p = [center[i] + su * half_u * u_axis[i] + sv * half_v * v_axis[i] for i in range(3)]
        pos += rnd_list(p)
        nor += rnd_list(n)
        # glTF UV origin is the image's top-left: v grows downwards
        uv += [rnd((su + 1) / 2 * uv_scale[0]), rnd((1 - sv) / 2 * uv_scale[1])]
    return pos, nor, uv, [0, 1, 2, 0, 2, 3]


def two_sided_quad(center, u_axis, v_axis, half_u, half_v, thickness):
    """A thin closed slab (box) so both faces are front faces with outward normals."""
    n = normalize(cross(u_axis, v_axis))
    return box(center, [u_axis, v_axis, n], [half_u, half_v, thickness / 2])


def box(center, axes, halves):
    """Closed box with 24 vertices (flat normals) along three orthonormal axes."""
    pos, nor, uv, idx = [], [], [], []
    for a in range(3):
        for sign in (1, -1):
            n = [sign * c for c in axes[a]]
            u = axes[(a + 1) % 3]
            v = axes[(a + 2) % 3]
            hu, hv = halves[(a + 1) % 3], halves[(a + 2) % 3]
            if sign < 0:
                u, v, hu, hv = v, u, hv, hu  # keep u x v = n
            c = [center[i] + n[i] * halves[a] for i in range(3)]
            p, q, t, k = quad(c, u, v, hu, hv)
            base = len(pos) // 3
            pos += p
            nor += q
            uv += t
            idx += [base + i for i in k]
    return pos, nor, uv, idx


def uv_sphere(center, radius, rings=48, segments=96):
    """UV sphere, outward normals, CCW seen from outside, v = 0 at the north pole."""
    pos, nor, uv, idx = [], [], [], []
    for r in range(rings + 1):
        theta = math.pi * r / rings
        for s in range(segments + 1):
            phi = 2 * math.pi * s / segments
            n = [math.sin(theta) * math.sin(phi), math.cos(theta), math.sin(theta) * math.cos(phi)]
            nor += rnd_list(n)
            pos += rnd_list([center[i] + radius * n[i] for i in range(3)])
            uv += [rnd(s / segments), rnd(r / rings)]
    row = segments + 1
    for r in range(rings):
        for s in range(segments):
            a, b = r * row + s, (r + 1) * row + s
            if r != 0:
                idx += [a, b, a + 1]
            if r != rings - 1:
                idx += [a + 1, b, b + 1]
    return pos, nor, uv, idx


def png_rgb(width, height, pixel):
    """Minimal deterministic PNG (8-bit RGB, no filtering) from pixel(x, y) -> (r, g, b)."""
    raw = bytearray()
    for y in range(height):
        raw.append(0)
        for x in range(width):
            raw += bytes(pixel(x, y))

    def chunk(tag, data):
        return (struct.pack(">I", len(data)) + tag + data
                + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF))

    ihdr = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr)
            + chunk(b"IDAT", zlib.compress(bytes(raw), 9)) + chunk(b"IEND", b""))


def checker_png(size=64, light=(204, 196, 180), dark=(58, 64, 74)):
    half = size // 2
    return png_rgb(size, size, lambda x, y: light if (x < half) == (y < half) else dark)


# ---------------------------------------------------------------------------------------------
# The scene
# ---------------------------------------------------------------------------------------------

def pbr(name, base, metallic=0.0, roughness=1.0, texture=None, extensions=None):
    m = {"name": name, "pbrMetallicRoughness": {
        "baseColorFactor": rnd_list(list(base) + [1.0] if len(base) == 3 else base),
        "metallicFactor": metallic, "roughnessFactor": roughness}}
    if texture is not None:
        m["pbrMetallicRoughness"]["baseColorTexture"] = {"index": texture}
    if extensions:
        m["extensions"] = extensions
    return m


def build():
    doc = Document()

    # Camera first: the renderer uses the first camera in node order.
    eye, target = [0.08, 0.46, 1.0], [0.03, 0.12, -0.12]
    doc.j["cameras"].append({"name": "view", "type": "perspective", "perspective": {
        "aspectRatio": 1.5, "yfov": 0.6, "znear": 0.01, "zfar": 100.0}})
    doc.add_node({"name": "camera", "camera": 0, "translation": rnd_list(eye),
                  "rotation": rnd_list(look_at_quat(eye, target), 7)})

    # Room: checkerboard floor, back and side walls, ceiling and a wall behind the camera
    # (so reflections and refractions never see the black background).
    checker = doc.add_png_texture(checker_png(), "checker")
    floor_mat = doc.add_material(pbr("floor", (1, 1, 1), roughness=0.8, texture=checker))
    back_mat = doc.add_material(pbr("wall_back", (0.32, 0.45, 0.62)))
    side_mat = doc.add_material(pbr("wall_side", (0.75, 0.62, 0.42)))
    white_mat = doc.add_material(pbr("wall_white", (0.78, 0.78, 0.76)))
    X, Y, Z = [1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0]
    NX, NZ = [-1.0, 0, 0], [0, 0, -1.0]
    room_w, room_d, room_h = 2.4, 3.5, 1.6     # x in [-1.2, 1.2], z in [-1.2, 2.3]
    z0, z1 = -1.2, 2.3
    zc, x0, x1 = (z0 + z1) / 2, -room_w / 2, room_w / 2
    # floor: normal +Y = u x v with u = +X, v = -Z; one check = 0.1 m (texture holds 2x2)
    pieces = [
        ("floor", quad([0, 0, zc], X, NZ, room_w / 2, room_d / 2, (room_w / 0.2, room_d / 0.2)), floor_mat),
        ("wall_back", quad([0, room_h / 2, z0], X, Y, room_w / 2, room_h / 2), back_mat),
        ("wall_front", quad([0, room_h / 2, z1], NX, Y, room_w / 2, room_h / 2), white_mat),
        ("wall_left", quad([x0, room_h / 2, zc], NZ, Y, room_d / 2, room_h / 2), side_mat),
        ("wall_right", quad([x1, room_h / 2, zc], Z, Y, room_d / 2, room_h / 2), side_mat),
        ("ceiling", quad([0, room_h, zc], X, Z, room_w / 2, room_d / 2), white_mat),
    ]
    for name, (p, n, t, i), mat in pieces:
        doc.add_node({"name": name, "mesh": doc.add_mesh(name, p, n, t, i, mat)})

    # Mirror sphere (metal, roughness 0 -> perfect mirror).
    mirror_mat = doc.add_material(pbr("mirror", (0.92, 0.92, 0.92), metallic=1.0, roughness=0.0))
    r_m = 0.13
    p, n, t, i = uv_sphere([0, 0, 0], r_m)
    doc.add_node({"name": "mirror_sphere", "mesh": doc.add_mesh("mirror_sphere", p, n, t, i, mirror_mat),
                  "translation": [-0.3, r_m, -0.2]})

    # Solid glass sphere: transmission + volume -> refraction with ior 1.5, faint blue absorption.
    doc.use_extension("KHR_materials_transmission")
    doc.use_extension("KHR_materials_volume")
    doc.use_extension("KHR_materials_ior")
    glass_mat = doc.add_material(pbr("glass", (1, 1, 1), roughness=0.0, extensions={
        "KHR_materials_transmission": {"transmissionFactor": 1.0},
        "KHR_materials_volume": {"thicknessFactor": 0.16, "attenuationColor": [0.8, 0.9, 1.0],
                                 "attenuationDistance": 0.3},
        "KHR_materials_ior": {"ior": 1.5}}))
    r_g = 0.09
    p, n, t, i = uv_sphere([0, 0, 0], r_g)
    doc.add_node({"name": "glass_sphere", "mesh": doc.add_mesh("glass_sphere", p, n, t, i, glass_mat),
                  "translation": [0.2, r_g, -0.1]})

    # Thin red transparent panel (no volume: thin-walled, straight through, tints light and shadows).
    panel_mat = doc.add_material(pbr("red_filter", (1.0, 0.2, 0.12), roughness=0.05, extensions={
        "KHR_materials_transmission": {"transmissionFactor": 1.0}}))
    pw, ph = 0.2, 0.26
    yaw = math.radians(-32)
    u_axis = [math.cos(yaw), 0.0, -math.sin(yaw)]
    p, n, t, i = two_sided_quad([0, ph / 2, 0], u_axis, Y, pw / 2, ph / 2, 0.004)
    doc.add_node({"name": "red_panel", "mesh": doc.add_mesh("red_panel", p, n, t, i, panel_mat),
                  "translation": [-0.12, 0.0, 0.1]})

    # Real assets. GlassHurricaneCandleHolder is kept at its native scale (0.27 m tall) because
    # its attenuationDistance is given in world units. The Duck (mesh y in [9.9, 164] under its
    # own 0.01 scale) is scaled by 0.13 to about 0.2 m, lowered onto the floor and turned so
    # its beak (+X in the asset) points towards the front-left.
    doc.merge(os.path.join(REPO, "assets/gltf/GlassHurricaneCandleHolder/glTF-Binary/GlassHurricaneCandleHolder.glb"),
              "GlassHurricaneCandleHolder", [0.0, 0.0, -0.38], [0, 0, 0, 1], [1, 1, 1])
    doc.merge(os.path.join(REPO, "assets/gltf/Duck/glTF-Binary/Duck.glb"),
              "Duck", [0.4, -0.0129, -0.15], quat_axis_angle(Y, -120), [0.13, 0.13, 0.13])

    # Lights (all inside the closed room: a directional light would be blocked by the ceiling).
    # Warm key spot from the left casts the long shadows to the right (the red one included);
    # a point light high behind-right casts a second set towards the camera; a weak cool fill
    # from the front-right lifts the faces the camera sees. Floor irradiance is about 1.
    key_pos, key_aim = [-0.95, 0.85, 0.05], [0.05, 0.05, -0.05]
    doc.add_light({"type": "spot", "color": [1.0, 0.86, 0.7], "intensity": 1.5,
                   "spot": {"innerConeAngle": 0.35, "outerConeAngle": 0.6}},
                  "key_spot", key_pos, look_at_quat(key_pos, key_aim))
    doc.add_light({"type": "point", "color": [0.65, 0.78, 1.0], "intensity": 0.25},
                  "fill_point", [0.7, 0.7, 0.8])
    doc.add_light({"type": "point", "color": [0.9, 0.95, 1.0], "intensity": 0.5},
                  "back_point", [0.45, 1.25, -0.75])
    return doc


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=os.path.join(REPO, "assets/scenes/default.glb"))
    args = ap.parse_args()
    doc = build()
    size = doc.write_glb(args.out)
    print("wrote %s (%d bytes, %d nodes, %d meshes, %d materials, %d lights)" % (
        os.path.relpath(args.out, REPO), size, len(doc.j["nodes"]), len(doc.j["meshes"]),
        len(doc.j["materials"]), len(doc.lights)))


if __name__ == "__main__":
    main()
