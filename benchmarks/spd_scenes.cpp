// SPD-style scenes of analytic quadrics and their tessellation (see spd_scenes.h).
#include "benchmarks/spd_scenes.h"

#include <cmath>

#include <fmt/format.h>

#include "core/error.h"

namespace whitted::app {

namespace {

uint32_t classic(Scene& s, const char* name, Color kd, Color ks, float n) {
    Material m;
    m.name = name;
    m.model = MaterialModel::Classic;
    m.classic.kd = kd;
    m.classic.ka = kd * 0.1f;
    m.classic.ks = ks;
    m.classic.kr = ks;
    m.classic.n = n;
    s.materials.push_back(m);
    return uint32_t(s.materials.size() - 1);
}

void add_cylinder(Scene& s, const Vec3d& a, const Vec3d& b, double r0, double r1, uint32_t material) {
    Quadric q = make_quadric(r0 == r1 ? QuadricKind::Cylinder : QuadricKind::Cone, a, b, r0, r1, true);
    q.material = material;
    q.name = "q" + std::to_string(s.quadrics.size());
    s.quadrics.push_back(q);
}

void add_sphere(Scene& s, const Vec3d& c, double r, uint32_t material) {
    Sphere sp;
    sp.center = c;
    sp.radius = r;
    sp.material = material;
    s.spheres.push_back(sp);
}

/// Ground disc, three lights, a camera looking at `target` from `eye`.
void stage(Scene& s, const Vec3d& eye, const Vec3d& target, double ground, double ground_radius) {
    const uint32_t floor = classic(s, "ground", Color(0.6f, 0.55f, 0.45f), Color(0.f), 1.f);
    Quadric d = make_quadric(QuadricKind::Disc, {0, ground, 0}, {0, ground + 1, 0}, ground_radius, ground_radius, false);
    d.material = floor;
    d.name = "ground";
    s.quadrics.push_back(d);
    for (const Vec3d p : {Vec3d{4, 6, 5}, Vec3d{-5, 7, 3}, Vec3d{1, 8, -6}}) {
        Light l;
        l.type = LightType::Point;
        l.position = p;
        l.color = Color(1.f);
        l.intensity = float(dot(p, p)) * 0.45f;
        s.lights.push_back(l);
    }
    Camera c;
    const Vec3d z = normalize(eye - target), x = normalize(cross(Vec3d{0, 1, 0}, z)), y = cross(z, x);
    for (int r = 0; r < 3; ++r) {
        c.world_from_camera(r, 0) = x[r];
        c.world_from_camera(r, 1) = y[r];
        c.world_from_camera(r, 2) = z[r];
        c.world_from_camera(r, 3) = eye[r];
    }
    c.yfov = 40.0 * kPiD / 180.0;
    s.cameras.push_back(c);
    s.settings.ambient = Color(0.2f);
}

void branch(Scene& s, const Vec3d& base, const Vec3d& dir, double length, double radius, int depth, uint32_t wood,
            uint32_t leaf) {
    const Vec3d tip = base + dir * length;
    add_cylinder(s, base, tip, radius, radius * 0.7, wood);
    if (depth == 0) {
        add_sphere(s, tip, radius * 2.5, leaf);
        return;
    }
    // Two children, turned apart about an axis that rotates with depth.
    const Vec3d side = normalize(cross(dir, std::fabs(dir.y) < 0.9 ? Vec3d{0, 1, 0} : Vec3d{1, 0, 0}));
    const double turn = 0.5 + 0.3 * double(depth % 3);
    const Vec3d other = cross(dir, side);
    const double c = std::cos(turn), sn = std::sin(turn), spin = 1.1 * double(depth);
    const Vec3d axis = side * std::cos(spin) + other * std::sin(spin);
    for (const double sign : {1.0, -1.0})
        branch(s, tip, normalize(dir * c + axis * (sign * sn)), length * 0.75, radius * 0.7, depth - 1, wood, leaf);
}

}  // namespace

Scene make_spd_scene(const std::string& name, int size) {
    Scene s;
    s.source = "spd:" + name;
    if (name == "rings") {
        const uint32_t metal = classic(s, "ring", Color(0.5f, 0.45f, 0.35f), Color(0.5f), 40.f);
        const uint32_t ball = classic(s, "joint", Color(0.7f, 0.2f, 0.2f), Color(0.3f), 20.f);
        // Levels of a pyramid: (size + 2 - level)^2 rings in level `level`, each a heptagon.
        const int levels = size + 1;
        const double ring_r = 0.5, tube = 0.06;
        for (int level = 0; level < levels; ++level) {
            const int n = levels - level;
            for (int i = 0; i < n; ++i)
                for (int j = 0; j < n; ++j) {
                    const Vec3d c{(double(i) - 0.5 * double(n - 1)) * 1.2, 0.2 + 0.45 * double(level),
                                  (double(j) - 0.5 * double(n - 1)) * 1.2};
                    const double tilt = 0.3 * double((i + j + level) % 3);
                    const Vec3d u{std::cos(tilt), std::sin(tilt), 0.0}, v{0.0, 0.0, 1.0};
                    constexpr int kSides = 7;
                    for (int k = 0; k < kSides; ++k) {
                        const double a0 = 2.0 * kPiD * k / kSides, a1 = 2.0 * kPiD * (k + 1) / kSides;
                        const Vec3d p0 = c + (u * std::cos(a0) + v * std::sin(a0)) * ring_r;
                        const Vec3d p1 = c + (u * std::cos(a1) + v * std::sin(a1)) * ring_r;
                        add_cylinder(s, p0, p1, tube, tube, metal);
                        add_sphere(s, p0, tube * 1.5, ball);
                    }
                }
        }
        const double extent = 0.6 * double(levels) + 1.0;
        stage(s, {extent * 1.4, extent * 1.1, extent * 1.8}, {0, 0.3 * double(levels), 0}, -0.4, extent * 3);
    } else if (name == "tree") {
        const uint32_t wood = classic(s, "wood", Color(0.45f, 0.3f, 0.15f), Color(0.1f), 10.f);
        const uint32_t leaf = classic(s, "leaf", Color(0.2f, 0.6f, 0.2f), Color(0.3f), 30.f);
        branch(s, {0, 0, 0}, {0, 1, 0}, 1.2, 0.12, 4 + size, wood, leaf);
        stage(s, {4.5, 3.5, 6.0}, {0, 2.0, 0}, 0.0, 10.0);
    } else {
        throw Error(fmt::format("unknown SPD scene '{}': expected rings or tree", name));
    }
    return s;
}

Scene tessellate_quadrics(const Scene& in, int segments) {
    Scene s = in;
    s.quadrics.clear();
    for (const Quadric& q : in.quadrics) {
        Mesh m;
        m.name = q.name;
        m.material = q.material;
        auto vertex = [&](const Vec3d& p, const Vec3d& n) {
            m.positions.push_back(Vec3f(p));
            m.normals.push_back(Vec3f(normalize(n)));
            return uint32_t(m.positions.size() - 1);
        };
        auto fan = [&](double z, double r, double nz) {  // a cap or disc: centre + ring, facing nz
            const uint32_t c = vertex({0, 0, z}, {0, 0, nz});
            for (int k = 0; k < segments; ++k) {
                const double a0 = 2.0 * kPiD * k / segments, a1 = 2.0 * kPiD * (k + 1) / segments;
                const uint32_t v0 = vertex({r * std::cos(a0), r * std::sin(a0), z}, {0, 0, nz});
                const uint32_t v1 = vertex({r * std::cos(a1), r * std::sin(a1), z}, {0, 0, nz});
                if (nz > 0) m.indices.insert(m.indices.end(), {c, v0, v1});
                else m.indices.insert(m.indices.end(), {c, v1, v0});
            }
        };
        if (q.kind == QuadricKind::Disc) {
            fan(0.0, q.radius0, 1.0);
        } else {
            const double k = (q.radius1 - q.radius0) / q.height;
            for (int i = 0; i <= segments; ++i) {
                const double a = 2.0 * kPiD * i / segments, ca = std::cos(a), sa = std::sin(a);
                const Vec3d n{ca, sa, -k};
                vertex({q.radius0 * ca, q.radius0 * sa, 0.0}, n);
                vertex({q.radius1 * ca, q.radius1 * sa, q.height}, n);
            }
            for (int i = 0; i < segments; ++i) {
                const uint32_t a = uint32_t(2 * i), b = a + 1, c = a + 2, d = a + 3;
                m.indices.insert(m.indices.end(), {a, c, b, b, c, d});
            }
            if (q.caps) {
                if (q.radius0 > 0) fan(0.0, q.radius0, -1.0);
                if (q.radius1 > 0) fan(q.height, q.radius1, 1.0);
            }
        }
        s.meshes.push_back(std::move(m));
        Instance inst;
        inst.mesh = uint32_t(s.meshes.size() - 1);
        inst.world_from_object = q.world_from_object;
        inst.node_name = q.name;
        s.instances.push_back(inst);
    }
    return s;
}

}  // namespace whitted::app
