// The reference renderer (reference_renderer.h): Whitted (1980) as docs/integrator.md writes it,
// in double precision, by brute force. Read it top to bottom: geometry (rays and primitives),
// surface data at a hit, material coefficients, lights, the formula, pixels.
//
// It shares with production only plain data and the glTF -> Whitted material mapping
// (src/shading/material_mapping.h, checked on its own by tests/unit/test_material_mapping.cpp); camera
// rays, intersection, texture lookups, lights and the integrator are written here again.
#include "reference/reference_renderer.h"

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <limits>
#include <optional>

#include "core/error.h"
#include "integrator/camera.h"
#include "shading/material_mapping.h"

namespace whitted {

namespace {

using V3 = Vec3d;
constexpr uint32_t kNone = UINT32_MAX;
constexpr double kInf = std::numeric_limits<double>::infinity();

/// Secondary-ray origins leave their surface by this fraction of the magnitude of the point's and
/// the primitive's coordinates: far above the double-precision error of a hit point (~1e-15 of
/// it), far below one float ulp (1.2e-7), so it neither self-intersects nor skips what production
/// hits.
constexpr double kOffset = 0x1p-32;

V3 vmul(const V3& a, const V3& b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
V3 to_v3(const Color& c) { return {double(c.x), double(c.y), double(c.z)}; }
bool black(const V3& c) { return c.x <= 0.0 && c.y <= 0.0 && c.z <= 0.0; }

// ==== Geometry: rays and primitives ===========================================================

struct RRay {
    V3 org, dir;       ///< dir unit length
    double tnear = 0.0, tfar = kInf;
};

struct Triangle {
    V3 v[3];           ///< world space, transformed in double from the mesh's float positions
};

/// An instance with its world-space triangles and bounds.
struct WorldInstance {
    uint32_t mesh = 0;
    std::vector<Triangle> tris;
    V3 lo{kInf, kInf, kInf}, hi{-kInf, -kInf, -kInf};
};

struct RHit {
    double t = kInf;
    double b1 = 0.0, b2 = 0.0;  ///< barycentrics of vertices 1 and 2 (triangles)
    uint32_t geom = kNone, inst = kNone, prim = kNone;
    bool valid() const { return geom != kNone; }
};

/// Slab test of a ray against an axis-aligned box over [tnear, tfar].
bool hits_box(const RRay& r, const V3& lo, const V3& hi) {
    double t0 = r.tnear, t1 = r.tfar;
    for (int k = 0; k < 3; ++k) {
        const double inv = 1.0 / r.dir[k];
        double a = (lo[k] - r.org[k]) * inv, b = (hi[k] - r.org[k]) * inv;
        if (a > b) std::swap(a, b);
        if (std::isnan(a) || std::isnan(b)) {  // parallel to the slab: inside or not
            if (r.org[k] < lo[k] || r.org[k] > hi[k]) return false;
            continue;
        }
        t0 = std::max(t0, a);
        t1 = std::min(t1, b);
        if (t0 > t1) return false;
    }
    return true;
}

/// Watertight ray-triangle test (Woop, Benthin and Wald, "Watertight Ray/Triangle Intersection",
/// JCGT 2013) in double: shear the triangle into the ray's frame, then three edge functions.
/// Both faces are hit; t in (tnear, tfar].
struct ShearedRay {
    int kx, ky, kz;
    double sx, sy, sz;
    explicit ShearedRay(const RRay& r) {
        const V3 a{std::fabs(r.dir.x), std::fabs(r.dir.y), std::fabs(r.dir.z)};
        kz = a.x > a.y ? (a.x > a.z ? 0 : 2) : (a.y > a.z ? 1 : 2);
        kx = (kz + 1) % 3;
        ky = (kx + 1) % 3;
        if (r.dir[kz] < 0.0) std::swap(kx, ky);  // keep the winding
        sx = r.dir[kx] / r.dir[kz];
        sy = r.dir[ky] / r.dir[kz];
        sz = 1.0 / r.dir[kz];
    }
};

bool intersect_triangle(const RRay& r, const ShearedRay& s, const Triangle& tri, double& t, double& b1, double& b2) {
    const V3 A = tri.v[0] - r.org, B = tri.v[1] - r.org, C = tri.v[2] - r.org;
    const double ax = A[s.kx] - s.sx * A[s.kz], ay = A[s.ky] - s.sy * A[s.kz];
    const double bx = B[s.kx] - s.sx * B[s.kz], by = B[s.ky] - s.sy * B[s.kz];
    const double cx = C[s.kx] - s.sx * C[s.kz], cy = C[s.ky] - s.sy * C[s.kz];
    const double U = cx * by - cy * bx;  // weight of vertex 0
    const double V = ax * cy - ay * cx;  // weight of vertex 1
    const double W = bx * ay - by * ax;  // weight of vertex 2
    if ((U < 0.0 || V < 0.0 || W < 0.0) && (U > 0.0 || V > 0.0 || W > 0.0)) return false;
    const double det = U + V + W;
    if (det == 0.0) return false;
    const double T = U * (s.sz * A[s.kz]) + V * (s.sz * B[s.kz]) + W * (s.sz * C[s.kz]);
    t = T / det;
    if (!(t > r.tnear && t <= r.tfar)) return false;
    b1 = V / det;
    b2 = W / det;
    return true;
}

/// The roots of |o + t d - c| = r in (tnear, tfar], nearer first; returns how many (0 to 2).
int intersect_sphere(const RRay& r, const Sphere& sp, double t[2]) {
    const V3 oc = r.org - sp.center;
    const double b = dot(oc, r.dir), c = dot(oc, oc) - sp.radius * sp.radius;
    const double disc = b * b - c;
    if (!(disc >= 0.0)) return 0;
    const double q = std::sqrt(disc);
    int n = 0;
    for (const double root : {-b - q, -b + q})
        if (root > r.tnear && root <= r.tfar) t[n++] = root;
    return n;
}

/// The crossings of a quadric's surfaces in (tnear, tfar], ascending, with the face each
/// crosses (QuadricPoint::part; 0 to 4 crossings: a ray through a rim may report the side and
/// the cap). Plainly: the ray in object space, the side's quadratic in long double with the
/// textbook roots, each cap and disc as a plane crossing within its radius; independent of the
/// renderer's interval form (accel/common/quadric.h).
int intersect_quadric(const RRay& r, const Quadric& q, double t[4], uint32_t face[4]) {
    const V3 o = q.object_from_world.apply_point(r.org), d = q.object_from_world.apply_vector(r.dir);
    int n = 0;
    auto keep = [&](double root, uint32_t f) {
        if (root > r.tnear && root <= r.tfar) t[n] = root, face[n++] = f;
    };
    auto plane_z = [&](double z, double r_in, double r_out, uint32_t f) {
        if (d.z == 0.0) return;
        const double root = (z - o.z) / d.z;
        const double x = o.x + root * d.x, y = o.y + root * d.y, rr = x * x + y * y;
        if (rr <= r_out * r_out && rr >= r_in * r_in) keep(root, f);
    };
    if (q.kind == QuadricKind::Disc) {
        plane_z(0.0, q.inner_radius, q.radius0, 0);
        return n;
    }
    using L = long double;
    const L k = (L(q.radius1) - L(q.radius0)) / L(q.height);
    const L ro = L(q.radius0) + k * L(o.z);
    const L a = L(d.x) * d.x + L(d.y) * d.y - k * k * d.z * d.z;
    const L b = 2 * (L(o.x) * d.x + L(o.y) * d.y - k * d.z * ro);
    const L c = L(o.x) * o.x + L(o.y) * o.y - ro * ro;
    std::vector<L> roots;
    if (a != 0) {
        const L disc = b * b - 4 * a * c;
        if (disc >= 0) roots = {(-b - std::sqrt(disc)) / (2 * a), (-b + std::sqrt(disc)) / (2 * a)};
    } else if (b != 0) {
        roots = {-c / b};
    }
    for (const L root : roots) {
        const double z = double(L(o.z) + root * L(d.z));
        if (z >= 0.0 && z <= q.height) keep(double(root), 0);
    }
    if (q.caps) {
        plane_z(0.0, 0.0, q.radius0, 1);
        plane_z(q.height, 0.0, q.radius1, 2);
    }
    for (int i = 1; i < n; ++i)  // insertion sort by t, faces alongside
        for (int j = i; j > 0 && t[j] < t[j - 1]; --j) std::swap(t[j], t[j - 1]), std::swap(face[j], face[j - 1]);
    return n;
}

bool intersect_plane(const RRay& r, const Plane& pl, double& t) {
    const double denom = dot(pl.normal, r.dir);
    if (denom == 0.0 || std::isnan(denom)) return false;
    t = dot(pl.normal, pl.point - r.org) / denom;
    return t > r.tnear && t <= r.tfar && std::isfinite(t);
}

// ==== The renderer =============================================================================

/// The scene's triangles in world space, built once and shared by every thread.
struct World {
    std::vector<WorldInstance> instances;
    std::vector<Mat4d> normal_xf;  ///< per instance: inverse transpose of world_from_object

    explicit World(const Scene& scene) {
        instances.resize(scene.instances.size());
        for (uint32_t i = 0; i < scene.instances.size(); ++i) {
            WorldInstance& wi = instances[i];
            wi.mesh = scene.instances[i].mesh;
            wi.tris.resize(scene.meshes[wi.mesh].triangle_count());
            for (uint32_t p = 0; p < wi.tris.size(); ++p) {
                scene.world_triangle(i, p, wi.tris[p].v);  // transformed in double
                for (const V3& v : wi.tris[p].v)
                    for (int k = 0; k < 3; ++k) {
                        wi.lo[k] = std::min(wi.lo[k], v[k]);
                        wi.hi[k] = std::max(wi.hi[k], v[k]);
                    }
            }
            normal_xf.push_back(scene.instances[i].world_from_object.inverse_affine().transposed());
        }
    }
};

/// Traces one pixel's ray tree at a time (one object per thread: it records the tree).
class Reference {
public:
    Reference(const Scene& scene, const RenderSettings& rs, const World& world)
        : m_scene(scene), m_rs(rs), m_instances(world.instances), m_normal_xf(world.normal_xf) {}

    /// Radiance along a camera ray through image position (x, y) and its ray tree.
    V3 pixel(const RRay& camera_ray, std::vector<ReferenceHitRecord>& tree, std::vector<ReferenceShadowRecord>& shadows) const {
        m_tree = &tree;
        m_shadows = &shadows;
        return trace(camera_ray, RayKind::Camera, 0);
    }

private:
    // ---- Surface data at a hit ----------------------------------------------------------------

    struct Surface {
        V3 p;               ///< the hit point, on the surface
        V3 p_shadow;        ///< shadow-ray origin before the offset (Hanika's lift, as production)
        double scale = 0.0; ///< magnitude of the primitive's coordinates (for the offset)
        V3 ng, ns;          ///< unit geometric (front by winding) and shading normals
        double normal_spread = 0.0;  ///< max |n_i - n_j| of the triangle's world-space vertex normals
        double altitude = 0.0;       ///< the triangle's smallest altitude (world space)
        Vec2f uv[2]{};
        Vec4f color{1.f, 1.f, 1.f, 1.f};
        uint32_t material = 0;
    };

    const Material& material_of(uint32_t geom) const { return m_scene.materials[m_scene.geom_material(geom)]; }

    /// Barycentric interpolation of a vertex attribute, in double.
    template <typename T>
    static std::array<double, 4> interp(const std::vector<T>& a, const uint32_t* idx, double w0, double w1, double w2) {
        std::array<double, 4> out{};
        constexpr int n = sizeof(T) / sizeof(float);
        for (int k = 0; k < n; ++k) {
            const float* x = reinterpret_cast<const float*>(&a[idx[0]]);
            const float* y = reinterpret_cast<const float*>(&a[idx[1]]);
            const float* z = reinterpret_cast<const float*>(&a[idx[2]]);
            out[size_t(k)] = double(x[k]) * w0 + double(y[k]) * w1 + double(z[k]) * w2;
        }
        return out;
    }

    Surface surface(const RRay& ray, const RHit& hit) const {
        Surface s;
        const V3 hit_point = ray.org + ray.dir * hit.t;
        switch (m_scene.geom_kind(hit.geom)) {
            case GeomKind::Sphere: {
                const Sphere& sp = m_scene.sphere_of(hit.geom);
                V3 n = hit_point - sp.center;
                const double len = length(n);
                n = len > 0.0 ? n / len : -ray.dir;
                s.p = s.p_shadow = sp.center + n * sp.radius;
                s.scale = sp.radius;
                s.ng = s.ns = n;
                const double u = std::atan2(n.x, n.z) / (2.0 * kPiD) + 0.5, v = std::acos(std::clamp(n.y, -1.0, 1.0)) / kPiD;
                s.uv[0] = s.uv[1] = Vec2f{float(u), float(v)};
                s.material = sp.material;
                return s;
            }
            case GeomKind::Quadric: {
                const Quadric& q = m_scene.quadric_of(hit.geom);
                const QuadricPoint qp = quadric_point(q, hit_point, int(hit.prim));
                s.p = s.p_shadow = qp.p;
                s.scale = 0.5 * length(quadric_bounds(q).diagonal());  // the object's size, as a sphere's radius
                s.ng = s.ns = qp.n;
                s.uv[0] = s.uv[1] = Vec2f{float(qp.u), float(qp.v)};
                s.material = q.material;
                return s;
            }
            case GeomKind::Plane: {
                const Plane& pl = m_scene.plane_of(hit.geom);
                s.p = s.p_shadow = hit_point - pl.normal * dot(pl.normal, hit_point - pl.point);
                s.scale = max_abs(pl.point);
                s.ng = s.ns = pl.normal;
                const V3 rel = s.p - pl.point;
                s.uv[0] = s.uv[1] = Vec2f{float(dot(rel, pl.u_axis)), float(dot(rel, cross(pl.normal, pl.u_axis)))};
                s.material = pl.material;
                return s;
            }
            case GeomKind::Mesh: break;
        }
        const Mesh& mesh = m_scene.meshes[hit.geom];
        const Triangle& tri = m_instances[hit.inst].tris[hit.prim];
        const uint32_t* idx = &mesh.indices[size_t(hit.prim) * 3];
        const double w1 = hit.b1, w2 = hit.b2, w0 = 1.0 - w1 - w2;
        s.material = mesh.material;
        s.p = s.p_shadow = tri.v[0] * w0 + tri.v[1] * w1 + tri.v[2] * w2;
        s.scale = std::max({max_abs(tri.v[0]), max_abs(tri.v[1]), max_abs(tri.v[2])});
        const V3 twice_area = cross(tri.v[1] - tri.v[0], tri.v[2] - tri.v[0]);
        s.ng = normalize(twice_area);
        const double longest = std::max({length(tri.v[1] - tri.v[0]), length(tri.v[2] - tri.v[1]), length(tri.v[0] - tri.v[2])});
        s.altitude = longest > 0.0 ? length(twice_area) / longest : 0.0;
        if (!is_finite(s.ng) || s.ng == V3(0.0)) s.ng = -ray.dir;  // degenerate triangle: face the ray
        const Mat4d& world = m_scene.instances[hit.inst].world_from_object;
        if (!mesh.normals.empty()) {
            // Shadow origin on the smooth surface the vertex normals describe (Hanika, "Hacking the
            // Shadow Terminator", Ray Tracing Gems II, 2021), as production: the point lifted onto
            // each vertex's tangent plane (only upwards), blended barycentrically, in object space.
            const V3 a(mesh.positions[idx[0]]), b(mesh.positions[idx[1]]), c(mesh.positions[idx[2]]);
            const V3 po = a * w0 + b * w1 + c * w2;
            auto lift = [&](const V3& pv, const Vec3f& nv) { return V3(nv) * std::min(0.0, dot(po - pv, V3(nv))); };
            const V3 delta = lift(a, mesh.normals[idx[0]]) * w0 + lift(b, mesh.normals[idx[1]]) * w1 +
                             lift(c, mesh.normals[idx[2]]) * w2;
            if (delta != V3(0.0) && is_finite(delta)) s.p_shadow = world.apply_point(po - delta);
        }
        if (!mesh.uv0.empty()) { auto t = interp(mesh.uv0, idx, w0, w1, w2); s.uv[0] = {float(t[0]), float(t[1])}; }
        if (!mesh.uv1.empty()) { auto t = interp(mesh.uv1, idx, w0, w1, w2); s.uv[1] = {float(t[0]), float(t[1])}; }
        if (!mesh.colors.empty()) {
            auto c = interp(mesh.colors, idx, w0, w1, w2);
            s.color = {float(c[0]), float(c[1]), float(c[2]), float(c[3])};
        }
        // Shading normal: interpolated vertex normals through the normal matrix, then the normal map.
        s.ns = s.ng;
        if (!mesh.normals.empty()) {
            const auto n = interp(mesh.normals, idx, w0, w1, w2);
            const V3 wn = normalize(m_normal_xf[hit.inst].apply_vector({n[0], n[1], n[2]}));
            if (wn != V3(0.0) && is_finite(wn)) s.ns = wn;
            V3 vn[3];
            for (int k = 0; k < 3; ++k) vn[k] = normalize(m_normal_xf[hit.inst].apply_vector(V3(mesh.normals[idx[k]])));
            s.normal_spread = std::max({length(vn[0] - vn[1]), length(vn[1] - vn[2]), length(vn[2] - vn[0])});
            if (!std::isfinite(s.normal_spread)) s.normal_spread = 0.0;
        }
        const Material& mat = m_scene.materials[mesh.material];
        if (mat.model == MaterialModel::GltfPbr && mat.normal_texture.valid() && !mesh.tangents.empty()) {
            const auto t4 = interp(mesh.tangents, idx, w0, w1, w2);
            V3 t = world.apply_vector({t4[0], t4[1], t4[2]});
            t = normalize(t - s.ns * dot(s.ns, t));  // Gram-Schmidt against the shading normal
            if (t != V3(0.0) && is_finite(t)) {
                const V3 b = cross(s.ns, t) * (t4[3] < 0.0 ? -1.0 : 1.0);
                const Vec4f tex = texture(mat.normal_texture, s.uv, s);
                const double k = mat.normal_texture.scale;
                const V3 m{(tex.x * 2.0 - 1.0) * k, (tex.y * 2.0 - 1.0) * k, tex.z * 2.0 - 1.0};
                const V3 mapped = normalize(t * m.x + b * m.y + s.ns * m.z);
                if (mapped != V3(0.0) && is_finite(mapped)) s.ns = mapped;
            }
        }
        return s;
    }

    // ---- Textures: the finest level, the sampler's magnification filter, no MIP filtering ------

    static double srgb_to_linear(uint8_t v) {
        const double c = v / 255.0;
        return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
    }

    /// A coordinate reduced to one period of the wrap mode (glTF samplers, OpenGL 4.6 section 8.14).
    static double reduce(double u, WrapMode mode) {
        if (!std::isfinite(u)) return 0.0;
        if (mode == WrapMode::Repeat) return u - std::floor(u);
        if (mode == WrapMode::MirroredRepeat) return u - 2.0 * std::floor(0.5 * u);
        return std::clamp(u, 0.0, 1.0);
    }
    static int wrap(int i, int n, WrapMode mode) {
        if (mode == WrapMode::Repeat) return ((i % n) + n) % n;
        if (mode == WrapMode::MirroredRepeat) {
            i = ((i % (2 * n)) + 2 * n) % (2 * n);
            return i < n ? i : 2 * n - 1 - i;
        }
        return std::clamp(i, 0, n - 1);
    }

    /// Linear RGBA of texture `ref` at the point (1 without a texture).
    Vec4f texture(const TextureRef& ref, const Vec2f uv[2], const Surface& s) const {
        if (!ref.valid() || size_t(ref.texture) >= m_scene.textures.size()) return {1.f, 1.f, 1.f, 1.f};
        const Texture& tex = m_scene.textures[size_t(ref.texture)];
        double u = uv[ref.uv_set > 1 ? 0 : ref.uv_set].x, v = uv[ref.uv_set > 1 ? 0 : ref.uv_set].y;
        if (!ref.transform.identity()) {
            // KHR_texture_transform: uv' = offset + R(rotation) (scale uv).
            const TextureTransform& x = ref.transform;
            const double su = double(x.scale.x) * u, sv = double(x.scale.y) * v;
            const double c = std::cos(double(x.rotation)), sn = std::sin(double(x.rotation));
            u = x.offset.x + c * su + sn * sv;
            v = x.offset.y - sn * su + c * sv;
        }
        if (tex.kind == TextureKind::Checker) {
            // Point-sampled checkerboard: color_a where the cell parity is even. The world-space
            // one is read a small step inside the surface so faces on a cell boundary pick one cell
            // (as production: 1e-4 of the square, or 16 float ulps of the point if more).
            const Checker& ch = tex.checker;
            long parity = 0;
            if (ch.world_space) {
                const double step = std::max(1e-4 * ch.size, 16.0 * float(max_abs(s.p)) * double(FLT_EPSILON));
                const V3 q = (s.p - s.ng * step) / double(ch.size);
                if (!is_finite(q)) return {ch.color_a.x, ch.color_a.y, ch.color_a.z, 1.f};
                parity = long(std::floor(q.x)) + long(std::floor(q.y)) + long(std::floor(q.z));
            } else {
                parity = long(std::floor(u / ch.size)) + long(std::floor(v / ch.size));
            }
            const Color c = parity % 2 == 0 ? ch.color_a : ch.color_b;
            return {c.x, c.y, c.z, 1.f};
        }
        if (tex.levels.empty() || tex.levels[0].width <= 0 || tex.levels[0].height <= 0) return {1.f, 1.f, 1.f, 1.f};
        m_textured = true;
        const MipLevel& level = tex.levels[0];
        const int w = level.width, h = level.height;
        u = reduce(u, tex.wrap_s);
        v = reduce(v, tex.wrap_t);
        auto fetch = [&](int x, int y) {
            const uint8_t* p = &level.texels[(size_t(wrap(y, h, tex.wrap_t)) * size_t(w) + size_t(wrap(x, w, tex.wrap_s))) * 4];
            std::array<double, 4> c;
            for (int k = 0; k < 3; ++k) c[size_t(k)] = tex.srgb ? srgb_to_linear(p[k]) : p[k] / 255.0;
            c[3] = p[3] / 255.0;
            return c;
        };
        std::array<double, 4> c;
        if (tex.mag_filter == FilterMode::Nearest) {
            c = fetch(int(std::floor(u * w)), int(std::floor(v * h)));
        } else {
            // Bilinear between the four texel centres around the point.
            const double fx = u * w - 0.5, fy = v * h - 0.5;
            const int x0 = int(std::floor(fx)), y0 = int(std::floor(fy));
            const double tx = fx - x0, ty = fy - y0;
            const auto a = fetch(x0, y0), b = fetch(x0 + 1, y0), d = fetch(x0, y0 + 1), e = fetch(x0 + 1, y0 + 1);
            for (size_t k = 0; k < 4; ++k)
                c[k] = (a[k] * (1 - tx) + b[k] * tx) * (1 - ty) + (d[k] * (1 - tx) + e[k] * tx) * ty;
        }
        return {float(c[0]), float(c[1]), float(c[2]), float(c[3])};
    }

    // ---- Material coefficients at a point ------------------------------------------------------

    /// glTF inputs at the point: factors x textures x vertex colour (docs/materials.md).
    PbrSample pbr_inputs(const Material& m, const Surface& s) const {
        PbrSample p;
        const Vec4f bc = texture(m.base_color_texture, s.uv, s);
        p.base_color = {m.base_color.x * bc.x * s.color.x, m.base_color.y * bc.y * s.color.y,
                        m.base_color.z * bc.z * s.color.z, m.base_color.w * bc.w * s.color.w};
        const Vec4f mr = texture(m.metallic_roughness_texture, s.uv, s);
        p.metallic = std::clamp(m.metallic * mr.z, 0.f, 1.f);
        p.roughness = std::clamp(m.roughness * mr.y, 0.f, 1.f);
        p.transmission = std::clamp(m.transmission * texture(m.transmission_texture, s.uv, s).x, 0.f, 1.f);
        if (m.occlusion_texture.valid())
            p.occlusion = 1.f + m.occlusion_texture.scale * (texture(m.occlusion_texture, s.uv, s).x - 1.f);
        p.emissive = m.emissive * texture(m.emissive_texture, s.uv, s).xyz() * m.emissive_strength;
        p.specular = m.specular * texture(m.specular_texture, s.uv, s).w;
        p.specular_color = m.specular_color * texture(m.specular_color_texture, s.uv, s).xyz();
        if (m.specular_glossiness) apply_specular_glossiness(m, texture(m.specular_glossiness_texture, s.uv, s), p);
        return p;
    }

    /// Whitted's coefficients at the point: the scene file's as given (tinted by its colour texture
    /// and vertex colours), or the glTF mapping of the inputs.
    WhittedCoeffs coefficients(const Surface& s) const {
        const Material& m = m_scene.materials[s.material];
        if (m.model == MaterialModel::Classic) {
            WhittedCoeffs c = m.classic;
            Color tint = s.color.xyz();
            if (m.classic_color_texture.valid()) tint *= texture(m.classic_color_texture, s.uv, s).xyz();
            c.kd *= tint;
            c.ka *= tint;
            return c;
        }
        return map_gltf_material(m, pbr_inputs(m, s), m_rs.mapping);
    }

    /// glTF coverage alpha at a triangle hit (MASK cut-outs, BLEND).
    double alpha(const Material& m, const Surface& s) const {
        return std::clamp(double(m.base_color.w) * texture(m.base_color_texture, s.uv, s).w * s.color.w, 0.0, 1.0);
    }

    // ---- Ray queries: closest hit and shadow transmittance -------------------------------------

    /// Whether a candidate hit counts for a closest-hit query: glTF alpha MASK cut-outs never do,
    /// and camera rays skip back faces of single-sided glTF materials.
    bool accepted(const RRay& ray, const RHit& h, RayKind kind) const {
        if (m_scene.geom_kind(h.geom) != GeomKind::Mesh) return true;
        const Material& m = material_of(h.geom);
        if (m.model != MaterialModel::GltfPbr) return true;
        if (m.alpha_mode == AlphaMode::Mask && alpha(m, surface(ray, h)) < m.alpha_cutoff) return false;
        if (kind == RayKind::Camera && !m.double_sided) {
            const Triangle& t = m_instances[h.inst].tris[h.prim];
            if (dot(cross(t.v[1] - t.v[0], t.v[2] - t.v[0]), ray.dir) > 0.0) return false;
        }
        return true;
    }

    /// Calls f(hit) for every primitive the ray crosses in (tnear, tfar], instances first (their
    /// bounds tested before their triangles), then spheres, quadrics and planes.
    template <typename F>
    void for_each_crossing(const RRay& ray, F&& f) const {
        const ShearedRay sheared(ray);
        for (uint32_t i = 0; i < m_instances.size(); ++i) {
            const WorldInstance& wi = m_instances[i];
            if (wi.tris.empty() || !hits_box(ray, wi.lo, wi.hi)) continue;
            for (uint32_t p = 0; p < wi.tris.size(); ++p) {
                RHit h;
                if (intersect_triangle(ray, sheared, wi.tris[p], h.t, h.b1, h.b2)) {
                    h.geom = wi.mesh, h.inst = i, h.prim = p;
                    f(h);
                }
            }
        }
        for (size_t i = 0; i < m_scene.spheres.size(); ++i) {
            double t[2];
            const int n = intersect_sphere(ray, m_scene.spheres[i], t);
            for (int k = 0; k < n; ++k) {  // both crossings (shadow rays pass through)
                RHit h;
                h.t = t[k], h.geom = m_scene.sphere_geom_id(i), h.prim = 0;
                f(h);
            }
        }
        for (size_t i = 0; i < m_scene.quadrics.size(); ++i) {
            double t[4];
            uint32_t face[4];
            const int n = intersect_quadric(ray, m_scene.quadrics[i], t, face);
            for (int k = 0; k < n; ++k) {
                RHit h;
                h.t = t[k], h.geom = m_scene.quadric_geom_id(i), h.prim = face[k];
                f(h);
            }
        }
        for (size_t i = 0; i < m_scene.planes.size(); ++i) {
            RHit h;
            if (intersect_plane(ray, m_scene.planes[i], h.t)) {
                h.geom = m_scene.plane_geom_id(i), h.prim = 0;
                f(h);
            }
        }
    }

    /// The nearest accepted hit; on an exact tie the first in for_each_crossing's order.
    RHit closest(const RRay& ray, RayKind kind) const {
        RHit best;
        for_each_crossing(ray, [&](const RHit& h) {
            if (h.t < best.t && accepted(ray, h, kind)) best = h;
        });
        return best;
    }

    /// Light a surface crossing lets through (docs/integrator.md, "Shadow transmittance"): Kt of
    /// a scene-file material; for glTF 1 where a MASK cuts the surface away, else (1 - alpha) + alpha Kt
    /// (alpha = 1 unless BLEND); 0 for opaque surfaces.
    V3 crossing_transmittance(const RRay& ray, const RHit& h) const {
        const Material& m = material_of(h.geom);
        if (m.model == MaterialModel::Classic) return to_v3(m.classic.kt);
        const Surface s = surface(ray, h);
        if (m_scene.geom_kind(h.geom) != GeomKind::Mesh) return to_v3(coefficients(s).kt);
        double coverage = 1.0;
        if (m.alpha_mode == AlphaMode::Mask && alpha(m, s) < m.alpha_cutoff) return V3(1.0);
        if (m.alpha_mode == AlphaMode::Blend) coverage = alpha(m, s);
        const V3 kt = m.transmission > 0.f ? to_v3(coefficients(s).kt) : V3(0.0);
        return V3(1.0 - coverage) + kt * coverage;
    }

    /// s: the product of the transmittances of the distinct surfaces the shadow ray crosses. A
    /// crossing reported twice (a shared edge of one mesh instance, the same t) counts once.
    V3 shadow_transmittance(const RRay& ray) const {
        std::vector<RHit> hits;
        for_each_crossing(ray, [&](const RHit& h) { hits.push_back(h); });
        std::sort(hits.begin(), hits.end(), [](const RHit& a, const RHit& b) { return a.t < b.t; });
        V3 s(1.0);
        for (size_t i = 0; i < hits.size(); ++i) {
            bool duplicate = false;
            for (size_t j = 0; j < i && !duplicate; ++j)
                duplicate = hits[j].geom == hits[i].geom && hits[j].inst == hits[i].inst &&
                            std::fabs(hits[j].t - hits[i].t) <= 1e-9 * std::max(1.0, hits[i].t);
            if (duplicate) continue;
            s = vmul(s, crossing_transmittance(ray, hits[i]));
            if (black(s)) return V3(0.0);
        }
        return s;
    }

    /// A secondary ray leaving the surface to the side `side` points to.
    static RRay spawn(const Surface& s, const V3& from, const V3& side, const V3& dir) {
        const double m = std::max(max_abs(from), s.scale);
        return RRay{from + side * (kOffset * m), dir};
    }

    // ---- The formula -----------------------------------------------------------------------------

    /// I along `ray` at tree depth `depth` (docs/integrator.md):
    ///   I = emission + Ia Ka + sum_i Is_i fat_i s_i (kd (N.L_i) + Ks (N.H_i)^n) + Kt T + Kr R
    /// then Beer-Lambert absorption and glTF alpha BLEND.
    V3 trace(const RRay& ray, RayKind kind, int depth) const {
        const RHit hit = closest(ray, kind);
        ReferenceHitRecord rec;
        rec.depth = depth;
        if (!hit.valid()) {
            m_tree->push_back(rec);
            return to_v3(m_rs.integrator.background);  // no environment (refused)
        }
        m_textured = false;
        const Surface s = surface(ray, hit);
        rec.geom = hit.geom, rec.inst = hit.inst, rec.prim = hit.prim, rec.t = hit.t;
        rec.edge = m_scene.geom_kind(hit.geom) == GeomKind::Mesh ? std::min({1.0 - hit.b1 - hit.b2, hit.b1, hit.b2}) : 1.0;
        rec.cos = std::fabs(dot(s.ng, ray.dir));
        rec.b1 = hit.b1, rec.b2 = hit.b2;
        rec.normal_spread = s.normal_spread;
        rec.altitude = s.altitude;
        const WhittedCoeffs c = coefficients(s);
        rec.textured = m_textured;
        const size_t rec_index = m_tree->size();
        m_tree->push_back(rec);
        const Material& mat = m_scene.materials[s.material];

        // Orientation: front face by winding (the ray enters the medium); V, Ng and N toward the viewer.
        const V3 V = -ray.dir;
        const bool front = dot(s.ng, V) >= 0.0;
        const V3 Ng = front ? s.ng : -s.ng;
        V3 N = front ? s.ns : -s.ns;
        if (dot(N, V) <= 0.0) N = Ng;  // a shading normal facing away falls back to the geometric one

        V3 I = to_v3(c.emission);
        const bool unlit = mat.model == MaterialModel::GltfPbr && mat.unlit;
        if (!unlit) {
            I = I + vmul(to_v3(m_rs.integrator.ambient), to_v3(c.ka));  // Ia Ka
            I = I + direct(s, c, N, V, Ng, front, (*m_tree)[rec_index]);  // sum over the lights
            if (depth < m_rs.integrator.max_depth) {
                auto [kr, kt] = weights(c, std::clamp(dot(N, V), 0.0, 1.0));
                const V3 T = transmitted(ray, s, c, N, Ng, front, kt, kr, depth);  // TIR moves kt to kr
                const V3 R = black(kr) ? V3(0.0) : vmul(kr, trace(spawn(s, s.p, Ng, mirror(V, N, Ng)), RayKind::Reflection, depth + 1));
                I = I + T + R;
            }
        }
        // Beer-Lambert inside a volume, over the segment the ray travelled in it.
        if (!front && !c.thin && !black(to_v3(c.absorption))) {
            const V3 a = to_v3(c.absorption);
            I = vmul(I, V3(std::exp(-a.x * hit.t), std::exp(-a.y * hit.t), std::exp(-a.z * hit.t)));
        }
        // glTF alpha BLEND: alpha I + (1 - alpha) I_behind.
        if (mat.model == MaterialModel::GltfPbr && mat.alpha_mode == AlphaMode::Blend) {
            const double a = std::clamp(double(pbr_inputs(mat, s).base_color.w), 0.0, 1.0);
            if (a < 1.0) {
                const V3 behind = depth < m_rs.integrator.max_depth
                                      ? trace(spawn(s, s.p, -Ng, ray.dir), RayKind::Refraction, depth + 1)
                                      : to_v3(m_rs.integrator.background);
                I = I * a + behind * (1.0 - a);
            }
        }
        return V3(std::isfinite(I.x) ? I.x : 0.0, std::isfinite(I.y) ? I.y : 0.0, std::isfinite(I.z) ? I.z : 0.0);
    }

    /// sum_i Is_i fat_i s_i (kd (N.L_i) + Ks (N.H_i)^n), lights in scene order.
    V3 direct(const Surface& s, const WhittedCoeffs& c, const V3& N, const V3& V, const V3& Ng, bool front,
              ReferenceHitRecord& rec) const {
        V3 sum(0.0);
        if (black(to_v3(c.kd)) && black(to_v3(c.ks))) return sum;
        const V3 org = front ? s.p_shadow : s.p;
        for (const Light& light : m_scene.lights) {
            // L, the distance, Is and fat (docs/lights.md).
            V3 L;
            double d = kInf, fat = 1.0, spot = 1.0;
            if (light.type == LightType::Directional) {
                L = normalize(-light.direction);
            } else {
                const V3 to = light.position - s.p;
                d = length(to);
                L = d > 0.0 ? to / d : V3(0.0, 0.0, 1.0);
                fat = attenuation(light, d);
                if (light.type == LightType::Spot) spot = spot_falloff(light, L);
            }
            const V3 Is = to_v3(light.color) * double(light.intensity) * (fat * spot);
            const double n_dot_l = dot(N, L);
            if (black(Is) || n_dot_l <= 0.0) continue;  // nothing arrives, or from behind: no shadow ray
            // kd (N.L) + Ks (N.H)^n, Blinn's half vector.
            const V3 H = normalize(L + V);
            const double n_dot_h = std::max(0.0, dot(N, H));
            const V3 term = to_v3(c.kd) * n_dot_l + to_v3(c.ks) * std::pow(n_dot_h, double(c.n));
            if (black(term)) continue;  // 0 whatever s is
            if (!black(to_v3(c.ks)) && std::pow(n_dot_h, double(c.n)) > 1e-6) rec.highlight_n = std::max(rec.highlight_n, double(c.n));
            if (spot > 0.0 && spot < 1.0) rec.spot_ramp = true;
            rec.min_n_dot_l = std::min(rec.min_n_dot_l, n_dot_l);
            // s: a shadow ray from the point (moved off the surface) toward the light.
            RRay shadow = spawn(s, org, Ng, L);
            if (light.type != LightType::Directional) {
                const V3 to = light.position - shadow.org;
                const double dl = length(to);
                if (!(dl > 0.0)) continue;
                shadow.dir = to / dl;
                shadow.tfar = dl * (1.0 - 1e-5);  // as production: stop short of the light
            }
            const V3 sh = shadow_transmittance(shadow);
            m_shadows->push_back({sh, black(to_v3(c.kd)) ? c.n * (1.0 - n_dot_h) : 0.0});
            sum = sum + vmul(vmul(Is, sh), term);
        }
        return sum;
    }

    /// fat: inverse square windowed by glTF `range`, the classic min(1, 1/(c1 + c2 d + c3 d^2)), or 1.
    static double attenuation(const Light& light, double d) {
        switch (light.attenuation) {
            case Attenuation::None: return 1.0;
            case Attenuation::Classic: {
                const double den = light.classic_c.x + light.classic_c.y * d + light.classic_c.z * d * d;
                return den > 0.0 ? std::min(1.0, 1.0 / den) : 1.0;
            }
            case Attenuation::InverseSquare: break;
        }
        double fat = 1.0 / std::max(d * d, 1e-12);
        if (light.range > 0.f) {
            const double r = d / light.range, w = std::clamp(1.0 - r * r * r * r, 0.0, 1.0);
            fat *= w * w;
        }
        return fat;
    }

    /// glTF spot cone: 1 inside the inner cone, 0 outside the outer, the square of a linear ramp of cos between.
    static double spot_falloff(const Light& light, const V3& L) {
        const double cos_outer = std::cos(double(light.outer_cone)), cos_inner = std::cos(double(light.inner_cone));
        const double cd = dot(light.direction, -L);
        if (cd <= cos_outer) return 0.0;
        if (cd >= cos_inner || cos_inner <= cos_outer) return 1.0;
        const double t = (cd - cos_outer) / (cos_inner - cos_outer);
        return t * t;
    }

    /// Kr and Kt of the secondary rays: constant (Whitted 1980), or with --fresnel Schlick's
    /// F(theta) from the normal-incidence reflectance Ks, Kt taking (1 - F) / (1 - Ks).
    std::pair<V3, V3> weights(const WhittedCoeffs& c, double cos_v) const {
        V3 kr = to_v3(c.kr), kt = to_v3(c.kt);
        if (!m_rs.integrator.fresnel) return {kr, kt};
        const V3 ks = to_v3(c.ks);
        const double x = std::clamp(1.0 - cos_v, 0.0, 1.0), x5 = x * x * x * x * x;
        for (int i = 0; i < 3; ++i) {
            const double F = ks[i] + (1.0 - ks[i]) * x5;
            kr[i] = ks[i] > 0.0 ? kr[i] * F / ks[i] : 0.0;
            kt[i] = ks[i] < 1.0 ? kt[i] * (1.0 - F) / (1.0 - ks[i]) : 0.0;
        }
        return {kr, kt};
    }

    /// R = 2 (N.V) N - V; about Ng instead where N would send it under the surface.
    static V3 mirror(const V3& V, const V3& N, const V3& Ng) {
        V3 R = N * (2.0 * dot(N, V)) - V;
        if (dot(R, Ng) <= 0.0) R = Ng * (2.0 * dot(Ng, V)) - V;
        return normalize(R);
    }

    /// Kt T: Snell's law (straight on through thin-walled surfaces); on total internal reflection,
    /// or a refracted ray that would not cross the surface, Kt joins Kr and T is 0.
    V3 transmitted(const RRay& ray, const Surface& s, const WhittedCoeffs& c, const V3& N, const V3& Ng, bool front,
                   const V3& kt, V3& kr, int depth) const {
        if (black(kt)) return V3(0.0);
        V3 dir = ray.dir;
        if (!c.thin) {
            const double eta = front ? 1.0 / c.ior : double(c.ior);  // n_incident / n_transmitted
            const double cos_i = -dot(N, ray.dir);
            const double sin2_t = eta * eta * std::max(0.0, 1.0 - cos_i * cos_i);
            std::optional<V3> T;
            if (sin2_t < 1.0) T = normalize(ray.dir * eta + N * (eta * cos_i - std::sqrt(1.0 - sin2_t)));
            if (!T || dot(*T, Ng) >= 0.0) {
                kr = kr + kt;
                return V3(0.0);
            }
            dir = *T;
        }
        return vmul(kt, trace(spawn(s, s.p, -Ng, dir), RayKind::Refraction, depth + 1));
    }

    const Scene& m_scene;
    const RenderSettings& m_rs;
    const std::vector<WorldInstance>& m_instances;
    const std::vector<Mat4d>& m_normal_xf;
    mutable std::vector<ReferenceHitRecord>* m_tree = nullptr;  // the pixel being traced
    mutable std::vector<ReferenceShadowRecord>* m_shadows = nullptr;
    mutable bool m_textured = false;  // an image texture was read since the flag was cleared
};

/// The camera ray through image position (x, y) (pixels, (0, 0) = top-left corner), glTF camera
/// conventions (looks down -Z, +Y up), as docs/cli.md describes the image: square pixels.
RRay camera_ray(const Camera& cam, int width, int height, double x, double y) {
    const Mat4d& m = cam.world_from_camera;
    const V3 origin = m.apply_point(V3(0.0));
    const V3 right = normalize(m.apply_vector({1, 0, 0})), up = normalize(m.apply_vector({0, 1, 0}));
    const V3 forward = normalize(m.apply_vector({0, 0, -1}));
    const double aspect = double(width) / double(height);
    const double half_h = cam.type == CameraType::Perspective ? std::tan(cam.yfov * 0.5) : cam.ymag;
    const double half_w = half_h * aspect;
    const double sx = (x * (2.0 / width) - 1.0) * half_w, sy = (1.0 - y * (2.0 / height)) * half_h;
    const double znear = std::max(0.0, cam.znear), zfar = cam.zfar > 0 ? cam.zfar : 0.0;
    RRay r;
    if (cam.type == CameraType::Perspective) {
        const V3 d = forward + right * sx + up * sy;
        const double len = length(d);
        r.org = origin;
        r.dir = d / len;
        r.tnear = znear * len;  // the near and far planes are distances along the view axis
        r.tfar = zfar > 0 ? zfar * len : kInf;
    } else {
        r.org = origin + right * sx + up * sy;
        r.dir = forward;
        r.tnear = znear;
        r.tfar = zfar > 0 ? zfar : kInf;
    }
    return r;
}

}  // namespace

void check_reference_supported(const Scene& scene, const RenderSettings& rs) {
    auto refuse = [](const std::string& what) { throw Error("reference renderer: " + what + " is not modelled"); };
    if (scene.environment) refuse("an environment (map, image-based light)");
    for (const Light& l : scene.lights)
        if (l.from_environment) refuse("a light extracted from an environment");
    if (rs.aa.mode != AaMode::Center) refuse(fmt::format("anti-aliasing '{}' (only one ray per pixel centre)", aa_mode_name(rs.aa.mode)));
    if (rs.integrator.min_weight != 0.f) refuse(fmt::format("--min-weight {} (only 0)", rs.integrator.min_weight));
    if (rs.aa.texture_filter != TextureFilter::None) refuse("--texture-filter mip (only none)");
    if (rs.crop) refuse("a crop");
    if (rs.integrator.max_depth < 0) throw Error("reference renderer: max depth must be >= 0");
    if (rs.camera < 0 || size_t(rs.camera) >= scene.cameras.size())
        throw Error(fmt::format("reference renderer: camera {} out of range (the scene has {})", rs.camera, scene.cameras.size()));
    if (scene.instanced_triangle_count() > kReferenceMaxTriangles)
        refuse(fmt::format("a scene of {} triangles (brute force: at most {})", scene.instanced_triangle_count(),
                           kReferenceMaxTriangles));
}

ReferenceImage render_reference(const Scene& scene, const RenderSettings& rs, int threads) {
    check_reference_supported(scene, rs);
    const Camera& cam = scene.cameras[size_t(rs.camera)];
    const ImageSize size = resolve_image_size(cam, rs.width, rs.height);
    ReferenceImage img;
    img.width = size.width;
    img.height = size.height;
    const size_t n = size_t(img.width) * size_t(img.height);
    img.radiance.resize(n);
    img.trees.resize(n);
    img.shadows.resize(n);
    const World world(scene);
    std::optional<tbb::global_control> limit;
    if (threads > 0) limit.emplace(tbb::global_control::max_allowed_parallelism, size_t(threads));
    tbb::parallel_for(0, img.height, [&](int y) {
        const Reference row(scene, rs, world);
        for (int x = 0; x < img.width; ++x) {
            const size_t i = size_t(y) * size_t(img.width) + size_t(x);
            const RRay r = camera_ray(cam, img.width, img.height, x + 0.5, y + 0.5);
            img.radiance[i] = row.pixel(r, img.trees[i], img.shadows[i]) * double(rs.exposure);
        }
    });
    return img;
}

}  // namespace whitted
