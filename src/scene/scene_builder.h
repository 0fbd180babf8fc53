// Building small scenes in code: materials, meshes (quads, boxes), cameras and point lights added
// to a Scene directly, for analytic test scenes, the stability probes and programs that make
// their scenes without a file.
#pragma once

#include <cmath>
#include <string>

#include "scene/scene.h"

namespace whitted {

/// Adds a Classic material (Whitted's (1980) coefficients) and returns its index.
inline uint32_t add_classic_material(Scene& s, const WhittedCoeffs& c, const std::string& name = "classic") {
    Material m;
    m.name = name;
    m.model = MaterialModel::Classic;
    m.classic = c;
    s.materials.push_back(m);
    return uint32_t(s.materials.size() - 1);
}

/// Adds a mesh with one instance (identity transform unless given) and returns the mesh index.
inline uint32_t add_mesh(Scene& s, Mesh mesh, const Mat4d& xf = Mat4d::identity()) {
    s.meshes.push_back(std::move(mesh));
    Instance inst;
    inst.mesh = uint32_t(s.meshes.size() - 1);
    inst.world_from_object = xf;
    s.instances.push_back(inst);
    return inst.mesh;
}

/// A planar quad a, b, c, d (counter-clockwise seen from its front) with flat normals.
inline Mesh make_quad(Vec3f a, Vec3f b, Vec3f c, Vec3f d, uint32_t material) {
    Mesh m;
    m.name = "quad";
    m.positions = {a, b, c, d};
    Vec3f n = normalize(cross(b - a, c - a));
    m.normals = {n, n, n, n};
    m.indices = {0, 1, 2, 0, 2, 3};
    m.material = material;
    return m;
}

/// Axis-aligned box [lo, hi] with outward faces (closed mesh, flat normals).
inline Mesh make_box(Vec3f lo, Vec3f hi, uint32_t material) {
    Mesh m;
    m.name = "box";
    m.material = material;
    auto face = [&](Vec3f a, Vec3f b, Vec3f c, Vec3f d) {
        uint32_t base = uint32_t(m.positions.size());
        Vec3f n = normalize(cross(b - a, c - a));
        for (Vec3f p : {a, b, c, d}) {
            m.positions.push_back(p);
            m.normals.push_back(n);
        }
        for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) m.indices.push_back(base + i);
    };
    const float x0 = lo.x, y0 = lo.y, z0 = lo.z, x1 = hi.x, y1 = hi.y, z1 = hi.z;
    face({x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1});  // +z
    face({x1, y0, z0}, {x0, y0, z0}, {x0, y1, z0}, {x1, y1, z0});  // -z
    face({x1, y0, z1}, {x1, y0, z0}, {x1, y1, z0}, {x1, y1, z1});  // +x
    face({x0, y0, z0}, {x0, y0, z1}, {x0, y1, z1}, {x0, y1, z0});  // -x
    face({x0, y1, z1}, {x1, y1, z1}, {x1, y1, z0}, {x0, y1, z0});  // +y
    face({x0, y0, z0}, {x1, y0, z0}, {x1, y0, z1}, {x0, y0, z1});  // -y
    return m;
}

/// Camera at `eye` looking along `forward` with the given up vector.
inline Camera make_camera(CameraType type, Vec3d eye, Vec3d forward, Vec3d up, double yfov_or_ymag) {
    Camera c;
    c.type = type;
    Vec3d f = normalize(forward);
    Vec3d r = normalize(cross(f, up));
    Vec3d u = cross(r, f);
    Mat4d m;
    for (int i = 0; i < 3; ++i) {
        m(i, 0) = r[i];
        m(i, 1) = u[i];
        m(i, 2) = -f[i];
        m(i, 3) = eye[i];
    }
    c.world_from_camera = m;
    if (type == CameraType::Perspective) c.yfov = yfov_or_ymag;
    else c.xmag = c.ymag = yfov_or_ymag;
    c.znear = 0.0;
    return c;
}

/// A point light at `pos`: radiant intensity `intensity * color` (renderer units, docs/lights.md).
inline Light point_light(Vec3d pos, float intensity, Color color = Color(1.f)) {
    Light l;
    l.type = LightType::Point;
    l.position = pos;
    l.intensity = intensity;
    l.color = color;
    return l;
}

}  // namespace whitted
