#include "scene/scene.h"

#include <algorithm>
#include <cmath>

namespace whitted {

void Scene::warn(const std::string& message) {
    if (std::find(warnings.begin(), warnings.end(), message) == warnings.end()) warnings.push_back(message);
}

Bounds3d Scene::world_bounds() const {
    // Object-space bounds per mesh once, then the 8 transformed corners per instance.
    std::vector<Bounds3d> mesh_bounds(meshes.size());
    for (size_t i = 0; i < meshes.size(); ++i) mesh_bounds[i] = meshes[i].bounds();
    Bounds3d b;
    for (const Instance& inst : instances) {
        const Bounds3d& mb = mesh_bounds[inst.mesh];
        if (!mb.empty()) b.extend(transform_bounds(inst.world_from_object, mb));
    }
    for (const Sphere& s : spheres) {
        b.extend(s.center - Vec3d(s.radius));
        b.extend(s.center + Vec3d(s.radius));
    }
    for (const Quadric& q : quadrics) b.extend(quadric_bounds(q));
    return b;
}

Quadric make_quadric(QuadricKind kind, const Vec3d& base, const Vec3d& apex, double radius0, double radius1,
                     bool caps, const Mat4d& transform) {
    Quadric q;
    q.kind = kind;
    const double len = length(apex - base);
    const Vec3d axis = (apex - base) / len;
    q.height = kind == QuadricKind::Disc ? 1.0 : len;
    q.radius0 = radius0;
    q.radius1 = kind == QuadricKind::Cone ? radius1 : radius0;
    q.caps = caps && kind != QuadricKind::Disc;
    // X: the coordinate axis least aligned with the axis, made perpendicular to it.
    int least = 0;
    for (int k = 1; k < 3; ++k)
        if (std::fabs(axis[k]) < std::fabs(axis[least])) least = k;
    Vec3d e{0.0, 0.0, 0.0};
    e[least] = 1.0;
    const Vec3d x = normalize(e - axis * dot(axis, e)), y = cross(axis, x);
    Mat4d frame;
    for (int r = 0; r < 3; ++r) {
        frame(r, 0) = x[r];
        frame(r, 1) = y[r];
        frame(r, 2) = axis[r];
        frame(r, 3) = base[r];
    }
    q.world_from_object = transform * frame;
    q.object_from_world = q.world_from_object.inverse_affine();
    return q;
}

QuadricPoint quadric_point(const Quadric& q, const Vec3d& world, int face, bool uvs) {
    QuadricPoint out;
    Vec3d o = q.object_from_world.apply_point(world);
    Vec3d n_obj{0.0, 0.0, 1.0};
    // Area scale of the transform: |det|^(2/3), exact for a similarity (for other maps a mean
    // that only sets the texture filter's footprint).
    const double area_scale = uvs ? std::cbrt(q.world_from_object.det3() * q.world_from_object.det3()) : 1.0;
    auto planar = [&](double r) {
        if (!uvs) return;
        const double rr = r > 0.0 ? r : 1.0;
        out.u = 0.5 + o.x / (2.0 * rr);
        out.v = 0.5 + o.y / (2.0 * rr);
        out.uv_area = 4.0 * rr * rr * area_scale;
    };
    if (q.kind == QuadricKind::Disc) {
        o.z = 0.0;
        planar(q.radius0);
    } else {
        const double k = (q.radius1 - q.radius0) / q.height;
        const double zc = std::clamp(o.z, 0.0, q.height);
        const double rho = std::sqrt(o.x * o.x + o.y * o.y);
        const double r_side = q.radius0 + k * zc;
        const double d_side = std::fabs(rho - r_side) + std::fabs(o.z - zc);
        double d_cap[2] = {std::fabs(o.z) + std::max(0.0, rho - q.radius0),
                           std::fabs(o.z - q.height) + std::max(0.0, rho - q.radius1)};
        out.part = 0;
        if (face >= 0 && face <= 2) out.part = q.caps ? face : 0;
        else if (q.caps && std::min(d_cap[0], d_cap[1]) < d_side) out.part = d_cap[0] <= d_cap[1] ? 1 : 2;
        if (out.part == 0) {
            if (rho > 0.0) {
                o.x *= r_side / rho;
                o.y *= r_side / rho;
            }
            o.z = zc;
            n_obj = r_side > 0.0 ? Vec3d{o.x, o.y, -k * r_side} : Vec3d{0.0, 0.0, k < 0.0 ? 1.0 : -1.0};
            if (rho == 0.0 && r_side > 0.0) n_obj = {1.0, 0.0, 0.0};  // on the axis: any radial direction
            if (uvs) {
                out.u = std::atan2(o.y, o.x) / (2.0 * kPiD) + 0.5;
                out.v = o.z / q.height;
                const double slant = std::sqrt(q.height * q.height + (q.radius1 - q.radius0) * (q.radius1 - q.radius0));
                const double r_mean = std::max(r_side, 1e-3 * std::max(q.radius0, q.radius1));
                out.uv_area = 2.0 * kPiD * r_mean * slant * area_scale;
            }
        } else {
            o.z = out.part == 1 ? 0.0 : q.height;
            n_obj = {0.0, 0.0, out.part == 1 ? -1.0 : 1.0};
            planar(out.part == 1 ? q.radius0 : q.radius1);
        }
    }
    out.p = q.world_from_object.apply_point(o);
    // Normals through the inverse transpose: n_world[i] = sum_j object_from_world(j, i) n_obj[j].
    const Mat4d& m = q.object_from_world;
    const Vec3d nw{m(0, 0) * n_obj.x + m(1, 0) * n_obj.y + m(2, 0) * n_obj.z,
                   m(0, 1) * n_obj.x + m(1, 1) * n_obj.y + m(2, 1) * n_obj.z,
                   m(0, 2) * n_obj.x + m(1, 2) * n_obj.y + m(2, 2) * n_obj.z};
    const double len = length(nw);
    out.n = len > 0.0 ? nw / len : Vec3d{0.0, 0.0, 1.0};
    if (!(out.uv_area > 0.0) || !std::isfinite(out.uv_area)) out.uv_area = 1.0;
    return out;
}

Bounds3d quadric_bounds(const Quadric& q) {
    const Mat4d& m = q.world_from_object;
    Bounds3d b;
    const bool disc = q.kind == QuadricKind::Disc;
    for (int end = 0; end < (disc ? 1 : 2); ++end) {
        const double z = end == 0 ? 0.0 : q.height;
        const double r = end == 0 ? q.radius0 : q.radius1;
        const Vec3d c = m.apply_point({0.0, 0.0, z});
        for (int k = 0; k < 3; ++k) {
            const double reach = r * std::sqrt(m(k, 0) * m(k, 0) + m(k, 1) * m(k, 1));
            Vec3d lo = c, hi = c;
            lo[k] -= reach;
            hi[k] += reach;
            b.extend(lo);
            b.extend(hi);
        }
    }
    return b;
}

size_t Scene::instanced_triangle_count() const {
    size_t n = 0;
    for (const Instance& inst : instances) n += meshes[inst.mesh].triangle_count();
    return n;
}

size_t Scene::mesh_triangle_count() const {
    size_t n = 0;
    for (const Mesh& m : meshes) n += m.triangle_count();
    return n;
}

}  // namespace whitted
