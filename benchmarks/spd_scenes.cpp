// SPD-style scenes of analytic quadrics and their tessellation (see spd_scenes.h).
#include "benchmarks/spd_scenes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

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
    q.name = fmt::format("q{}", s.quadrics.size());
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

/// Sphereflake (SPD "balls"): nine spheres a third of the size on each sphere, six about its
/// equator and three on a ring 60 degrees above it, the equator taken about the axis from its
/// parent; `depth` more levels below this one.
void flake(Scene& s, const Vec3d& centre, double radius, const Vec3d& axis, int depth, uint32_t material) {
    add_sphere(s, centre, radius, material);
    if (depth == 0) return;
    const Vec3d u = normalize(cross(axis, std::fabs(axis.y) < 0.9 ? Vec3d{0, 1, 0} : Vec3d{1, 0, 0}));
    const Vec3d v = cross(axis, u);
    const double child = radius / 3.0;
    for (int k = 0; k < 9; ++k) {
        const bool upper = k >= 6;
        const double azimuth = upper ? kPiD / 6.0 + 2.0 * kPiD * (k - 6) / 3.0 : 2.0 * kPiD * k / 6.0;
        const double elevation = upper ? kPiD / 3.0 : 0.0;
        const Vec3d d = (u * std::cos(azimuth) + v * std::sin(azimuth)) * std::cos(elevation) + axis * std::sin(elevation);
        flake(s, centre + d * (radius + child), child, d, depth - 1, material);
    }
}

/// A triangle with its face normal at each corner (own vertices: flat shading).
void add_flat_triangle(Mesh& m, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
    const Vec3f n(normalize(cross(b - a, c - a)));
    for (const Vec3d& p : {a, b, c}) {
        m.indices.push_back(uint32_t(m.positions.size()));
        m.positions.push_back(Vec3f(p));
        m.normals.push_back(n);
    }
}

/// Sierpinski tetrahedron (SPD "tetra"): the four corner tetrahedra of half the size, `depth`
/// times; each leaf's four faces.
void sierpinski(Mesh& m, const std::array<Vec3d, 4>& v, int depth) {
    if (depth == 0) {
        add_flat_triangle(m, v[0], v[2], v[1]);
        add_flat_triangle(m, v[0], v[1], v[3]);
        add_flat_triangle(m, v[1], v[2], v[3]);
        add_flat_triangle(m, v[2], v[0], v[3]);
        return;
    }
    for (int k = 0; k < 4; ++k) {
        std::array<Vec3d, 4> w;
        for (int i = 0; i < 4; ++i) w[size_t(i)] = (v[size_t(k)] + v[size_t(i)]) * 0.5;
        sierpinski(m, w, depth - 1);
    }
}

/// A value in [-1, 1] from a lattice point (integer hash; the same for every run and platform).
double lattice_noise(int i, int j) {
    uint32_t h = uint32_t(i) * 0x9E3779B1u ^ (uint32_t(j) + 0x7F4A7C15u) * 0x85EBCA77u;
    h ^= h >> 15;
    h *= 0x2C1B3C6Du;
    h ^= h >> 12;
    h *= 0x297A2D39u;
    h ^= h >> 15;
    return double(h) / double(0xFFFFFFFFu) * 2.0 - 1.0;
}

/// Fractal mountain (SPD "mount"): a triangle of 4^levels triangles whose heights come from
/// midpoint displacement on a triangular lattice (each new point the mean of its edge's ends plus
/// noise halving with the level, `roughness` at the first), so neighbouring triangles share their
/// edges' heights, over a pyramid `peak` high; the rim stays at height 0 and nothing goes below it
/// (no gap under the edge to look into).
Mesh fractal_mountain(int levels, const Vec3d& a, const Vec3d& b, const Vec3d& c, double peak, double roughness) {
    const int n = 1 << levels;  // lattice points (i, j), i + j <= n: a + (b - a) i / n + (c - a) j / n
    std::vector<double> h(size_t((n + 1) * (n + 1)), 0.0);
    auto at = [&](int i, int j) -> double& { return h[size_t(i * (n + 1) + j)]; };
    double scale = roughness;
    for (int step = n; step > 1; step /= 2, scale *= 0.5) {
        const int half = step / 2;
        // The midpoints of this level's edges: along i, along j, and the diagonals.
        for (int i = 0; i <= n; i += half)
            for (int j = 0; i + j <= n; j += half) {
                if (i % step == 0 && j % step == 0) continue;  // a point of an earlier level
                if (i == 0 || j == 0 || i + j == n) continue;    // the rim stays on the ground
                int i0 = i, j0 = j, i1 = i, j1 = j;
                if (i % step != 0 && j % step != 0) i0 -= half, j0 += half, i1 += half, j1 -= half;  // diagonal
                else if (i % step != 0) i0 -= half, i1 += half;
                else j0 -= half, j1 += half;
                at(i, j) = 0.5 * (at(i0, j0) + at(i1, j1)) + scale * lattice_noise(i, j);
            }
    }
    Mesh m;
    m.name = "mountain";
    auto point = [&](int i, int j) {
        const double u = double(i) / n, v = double(j) / n;
        const Vec3d p = a + (b - a) * u + (c - a) * v;
        // A peak over the centre (3 min(barycentric) is 1 there, 0 on the rim), roughened by the noise.
        const double peak_height = peak * 3.0 * std::min({u, v, 1.0 - u - v});
        return Vec3d{p.x, p.y + std::max(0.0, peak_height + at(i, j)), p.z};
    };
    for (int i = 0; i < n; ++i)
        for (int j = 0; i + j < n; ++j) {
            add_flat_triangle(m, point(i, j), point(i + 1, j), point(i, j + 1));
            if (i + j + 1 < n) add_flat_triangle(m, point(i + 1, j), point(i + 1, j + 1), point(i, j + 1));
        }
    return m;
}

/// A gear (SPD "gears"): `teeth` trapezoid teeth between radii `inner` and `outer` about the
/// y axis, `thickness` high, as flat triangles: the two faces (fans from the centre; the
/// outline is star-shaped about it) and the side walls.
void add_gear(Mesh& m, const Vec3d& centre, double inner, double outer, double thickness, int teeth, double turn) {
    std::vector<Vec3d> outline;  // counter-clockwise seen from +y, four points a tooth
    for (int k = 0; k < teeth; ++k)
        for (const auto& [frac, r] : {std::pair{0.0, inner}, std::pair{0.15, outer}, std::pair{0.45, outer}, std::pair{0.6, inner}}) {
            const double a = turn + 2.0 * kPiD * (double(k) + frac) / double(teeth);
            outline.push_back({r * std::cos(a), 0.0, -r * std::sin(a)});
        }
    const Vec3d up{0.0, thickness, 0.0};
    for (size_t i = 0; i < outline.size(); ++i) {
        const Vec3d a = centre + outline[i], b = centre + outline[(i + 1) % outline.size()];
        add_flat_triangle(m, centre + up, a + up, b + up);  // top face
        add_flat_triangle(m, centre, b, a);                 // bottom face
        add_flat_triangle(m, a, b, b + up);                 // side wall
        add_flat_triangle(m, a, b + up, a + up);
    }
}

/// Appends `m` with `material` and the instance placing it (named after it) by `world`.
void add_mesh(Scene& s, Mesh m, uint32_t material, const Mat4d& world = Mat4d()) {
    m.material = material;
    s.meshes.push_back(std::move(m));
    Instance inst;
    inst.mesh = uint32_t(s.meshes.size() - 1);
    inst.world_from_object = world;
    inst.node_name = s.meshes.back().name;
    s.instances.push_back(inst);
}

}  // namespace

const std::vector<std::string>& spd_scene_names() {
    static const std::vector<std::string> names{"rings", "tree", "balls", "tetra", "mount", "gears"};
    return names;
}

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
    } else if (name == "balls") {
        const uint32_t ball = classic(s, "ball", Color(0.6f, 0.45f, 0.35f), Color(0.5f), 40.f);
        flake(s, {0, 1.4, 0}, 1.0, {0, 1, 0}, size, ball);
        stage(s, {3.2, 3.4, 5.2}, {0, 1.2, 0}, 0.0, 12.0);
    } else if (name == "tetra") {
        const uint32_t matte = classic(s, "tetra", Color(0.75f, 0.7f, 0.45f), Color(0.f), 1.f);
        Mesh m;
        m.name = "tetra";
        const double e = 3.0;  // edge
        const double r = e / std::sqrt(3.0), height = e * std::sqrt(2.0 / 3.0);
        std::array<Vec3d, 4> v;
        for (int k = 0; k < 3; ++k) v[size_t(k)] = {r * std::cos(2.0 * kPiD * k / 3.0), 0.0, r * std::sin(2.0 * kPiD * k / 3.0)};
        v[3] = {0.0, height, 0.0};
        sierpinski(m, v, size + 1);
        add_mesh(s, std::move(m), matte);
        stage(s, {3.0, 3.6, 5.0}, {0, 1.0, 0}, 0.0, 12.0);
    } else if (name == "mount") {
        const uint32_t rock = classic(s, "rock", Color(0.5f, 0.45f, 0.35f), Color(0.f), 1.f);
        const uint32_t mirror = classic(s, "mirror", Color(0.1f), Color(0.8f), 60.f);
        const uint32_t glass = classic(s, "glass", Color(0.02f), Color(0.1f), 80.f);
        s.materials[glass].classic.kt = Color(0.85f);
        s.materials[glass].classic.ior = 1.5f;
        s.materials[glass].classic.thin = false;
        add_mesh(s, fractal_mountain(size + 3, {-4.0, 0.0, 3.0}, {4.0, 0.0, 3.0}, {0.0, 0.0, -4.0}, 2.0, 1.2), rock);
        add_sphere(s, {-1.6, 2.6, 1.2}, 0.5, glass);
        add_sphere(s, {0.0, 3.2, 0.2}, 0.5, mirror);
        add_sphere(s, {1.6, 2.6, 1.2}, 0.5, mirror);
        add_sphere(s, {0.0, 2.4, 2.2}, 0.5, mirror);
        stage(s, {0.0, 4.5, 8.5}, {0, 1.2, 0}, -0.01, 12.0);
    } else if (name == "gears") {
        // (size + 1)^2 gears of 16 teeth on a grid, their teeth reaching over to the neighbours';
        // every other one raised above them and turned half a tooth; shiny metal.
        const uint32_t metal = classic(s, "gear", Color(0.55f, 0.5f, 0.45f), Color(0.5f), 30.f);
        Mesh m;
        m.name = "gears";
        const int n = size + 1, teeth = 16;
        const double inner = 0.5, outer = 0.62, pitch = 2.0 * inner + 0.1;
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j) {
                const bool odd = (i + j) % 2 == 1;
                const Vec3d c{(double(i) - 0.5 * double(n - 1)) * pitch, odd ? 0.25 : 0.0, (double(j) - 0.5 * double(n - 1)) * pitch};
                add_gear(m, c, inner, outer, 0.2, teeth, odd ? kPiD / teeth : 0.0);
            }
        add_mesh(s, std::move(m), metal);
        const double extent = 0.5 * double(n) * pitch;
        stage(s, {extent * 1.2, extent * 1.6, extent * 2.0}, {0, 0, 0}, -0.01, extent * 4.0);
    } else {
        throw Error(fmt::format("unknown SPD scene '{}': expected one of {}", name, fmt::join(spd_scene_names(), ", ")));
    }
    return s;
}

Scene tessellate_quadrics(const Scene& in, int segments) {
    Scene s = in;
    s.quadrics.clear();
    for (const Quadric& q : in.quadrics) {
        Mesh m;
        m.name = q.name;
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
        add_mesh(s, std::move(m), q.material, q.world_from_object);
    }
    return s;
}

}  // namespace whitted::app
