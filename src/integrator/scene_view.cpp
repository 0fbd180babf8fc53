#include "integrator/scene_view.h"

#include <algorithm>
#include <cmath>

#include "shading/texture_sampling.h"

namespace whitted {

namespace {

Vec3f xf_point(const float* m, const Vec3f& p) {
    return {m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3], m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
            m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]};
}
Vec3f xf_vector(const float* m, const Vec3f& v) {
    return {m[0] * v.x + m[1] * v.y + m[2] * v.z, m[4] * v.x + m[5] * v.y + m[6] * v.z,
            m[8] * v.x + m[9] * v.y + m[10] * v.z};
}
Vec3f xf_normal(const float* n, const Vec3f& v) {
    return {n[0] * v.x + n[1] * v.y + n[2] * v.z, n[3] * v.x + n[4] * v.y + n[5] * v.z,
            n[6] * v.x + n[7] * v.y + n[8] * v.z};
}

template <typename T>
T interpolate(const std::vector<T>& a, uint32_t i0, uint32_t i1, uint32_t i2, float u, float v) {
    const float w = 1.f - u - v;
    const T& x = a[i0];
    const T& y = a[i1];
    const T& z = a[i2];
    if constexpr (std::is_same_v<T, Vec2f>) return {x.x * w + y.x * u + z.x * v, x.y * w + y.y * u + z.y * v};
    else if constexpr (std::is_same_v<T, Vec4f>)
        return {x.x * w + y.x * u + z.x * v, x.y * w + y.y * u + z.y * v, x.z * w + y.z * u + z.z * v,
                x.w * w + y.w * u + z.w * v};
    else return x * w + y * u + z * v;
}

/// Texture lookup through a material's reference; (1,1,1,1) when the reference is empty.
/// `uv_lod` (per UV set, see SurfacePoint::uv_lod) gives the MIP level: the footprint in texels is
/// its width in UV units times the texture size (geometric mean of width and height) times the
/// scale of KHR_texture_transform; -inf selects level 0 with the magnification filter.
/// Procedural textures also read the world position `p` and normal `n`.
Vec4f lookup(const Scene& scene, const TextureRef& ref, const Vec2f uv[2], const float uv_lod[2],
             const Vec3f& p = Vec3f(0.f), const Vec3f& n = Vec3f(0.f), float world_footprint = 0.f) {
    if (!ref.valid() || size_t(ref.texture) >= scene.textures.size()) return {1.f, 1.f, 1.f, 1.f};
    const uint32_t set = ref.uv_set > 1 ? 0 : ref.uv_set;
    Vec2f t = uv[set];
    float lod = uv_lod[set];
    const Texture& texture = scene.textures[size_t(ref.texture)];
    if (!ref.transform.identity()) {
        t = apply_texture_transform(ref.transform, t);
        const float area_scale = std::abs(ref.transform.scale.x * ref.transform.scale.y);
        if (area_scale > 0.f) lod += 0.5f * std::log2(area_scale);
    }
    if (texture.kind == TextureKind::Checker) {
        const float width = texture.checker.world_space ? world_footprint : lod > -kInfinity ? std::exp2(lod) : 0.f;
        const Color c = sample_checker(texture.checker, t, p, n, width);
        return {c.x, c.y, c.z, 1.f};
    }
    if (lod > -kInfinity && !texture.levels.empty())
        lod += 0.5f * std::log2(float(texture.levels[0].width) * float(texture.levels[0].height));
    return sample_texture(texture, t, lod);
}

/// Point lookups (no footprint): alpha tests during traversal and shadow transmittance.
constexpr float kNoFootprint[2] = {-kInfinity, -kInfinity};

}  // namespace

SceneView::SceneView(const Scene& scene, const MappingOptions& mapping) : m_scene(scene), m_mapping(mapping) {
    derive();
}

bool SceneView::update() {
    const std::vector<uint32_t> flags = m_mesh_flags;
    derive();
    return flags == m_mesh_flags;
}

void SceneView::derive() {
    const Scene& scene = m_scene;
    const uint32_t levels = m_environment ? m_analysis.prefilter_levels : 0;
    m_analysis = analyze_scene(scene, m_mapping);
    // Only the prefiltered levels the materials' glossy term reads (most of the map's build time);
    // built again only when animated materials read other levels.
    if (scene.environment && (!m_environment || levels != m_analysis.prefilter_levels))
        m_environment = std::make_shared<const EnvironmentMap>(*scene.environment, 0, EnvironmentMap::Use::Rendering,
                                                               m_analysis.prefilter_levels);
    // What a shadow ray keeps crossing a glTF material that is the same everywhere (no texture,
    // no vertex colour): computed once here instead of at every crossing.
    m_constant_shadow_kt.assign(scene.materials.size(), std::nullopt);
    for (size_t i = 0; i < scene.materials.size(); ++i) {
        const Material& m = scene.materials[i];
        const MaterialFeatures& f = m_analysis.materials[i];
        if (m.model == MaterialModel::GltfPbr && !f.textured && !f.vertex_colors) {
            SurfacePoint sp;
            sp.material = uint32_t(i);
            m_constant_shadow_kt[i] = transmitted_light(m, sp);
        }
    }
    m_directional_samples.assign(scene.lights.size(), LightSample{});
    for (size_t i = 0; i < scene.lights.size(); ++i)
        if (scene.lights[i].type == LightType::Directional)
            m_directional_samples[i] = whitted::sample_light(scene.lights[i], Vec3f(0.f));
    // Float transforms per instance; the normal matrix is inverted in double precision.
    m_xf.resize(scene.instances.size());
    for (size_t i = 0; i < scene.instances.size(); ++i) {
        const Mat4d& w = scene.instances[i].world_from_object;
        const Mat4d inv_t = w.inverse_affine().transposed();
        for (int r = 0; r < 3; ++r) {
            for (int c = 0; c < 4; ++c) m_xf[i].m[r * 4 + c] = float(w(r, c));
            for (int c = 0; c < 3; ++c) m_xf[i].n[r * 3 + c] = float(inv_t(r, c));
        }
    }
    // Which materials read a texture through UVs. The scene file's world-space checker (Whitted's
    // floor) reads the position, normal and footprint only: its hits skip the UV interpolation,
    // the sphere's atan2/acos and the log2 of the MIP level.
    m_needs_uv.resize(scene.materials.size());
    for (size_t i = 0; i < scene.materials.size(); ++i) {
        const Material& m = scene.materials[i];
        if (m.model != MaterialModel::Classic) {
            m_needs_uv[i] = 1;  // glTF textures are all UV-mapped (conservative for untextured ones)
            continue;
        }
        const TextureRef& ref = m.classic_color_texture;
        const bool world_checker = ref.valid() && size_t(ref.texture) < scene.textures.size() &&
                                   scene.textures[size_t(ref.texture)].kind == TextureKind::Checker &&
                                   scene.textures[size_t(ref.texture)].checker.world_space;
        m_needs_uv[i] = ref.valid() && !world_checker;
    }
    // What each geometry (meshes, spheres, planes) needs from traversal.
    m_mesh_flags.resize(scene.geometry_count());
    for (uint32_t g = 0; g < scene.geometry_count(); ++g) {
        const Material& m = scene.materials[scene.geom_material(g)];
        const bool is_mesh = scene.geom_kind(g) == GeomKind::Mesh;
        uint32_t f = 0;
        const bool cutout = is_mesh && m.model == MaterialModel::GltfPbr && m.alpha_mode == AlphaMode::Mask;
        const bool single_sided = is_mesh && m.model == MaterialModel::GltfPbr && !m.double_sided;
        if (cutout || single_sided) f |= kNeedsAccept;
        const bool transmissive = m.model == MaterialModel::Classic ? !is_black(m.classic.kt)
                                                                    : (m.transmission > 0.f || m.transmission_texture.valid() ||
                                                                       m.alpha_mode == AlphaMode::Blend ||
                                                                       m.diffuse_transmission > 0.f);
        if (cutout || transmissive) f |= kNeedsTransmittance;
        m_mesh_flags[g] = f;
    }
}

Vec3f SceneView::world_geometric_normal(const Hit& hit) const {
    const Mesh& mesh = m_scene.meshes[hit.geom];
    const InstanceXf& xf = m_xf[hit.inst];
    const uint32_t* idx = &mesh.indices[size_t(hit.prim) * 3];
    Vec3f p0 = xf_point(xf.m, mesh.positions[idx[0]]);
    Vec3f p1 = xf_point(xf.m, mesh.positions[idx[1]]);
    Vec3f p2 = xf_point(xf.m, mesh.positions[idx[2]]);
    return cross(p1 - p0, p2 - p0);
}

template <bool kAttributes>
SurfacePoint SceneView::surface(const Ray& ray, const Hit& hit, const RayCone& cone) const {
    switch (m_scene.geom_kind(hit.geom)) {
        case GeomKind::Sphere: return sphere_surface<kAttributes>(ray, hit, cone);
        case GeomKind::Quadric: return quadric_surface<kAttributes>(ray, hit, cone);
        case GeomKind::Plane: return plane_surface<kAttributes>(ray, hit, cone);
        case GeomKind::Mesh: break;
    }
    return mesh_surface<kAttributes>(ray, hit, cone);
}

template <bool kAttributes>
SurfacePoint SceneView::mesh_surface(const Ray& ray, const Hit& hit, const RayCone& cone) const {
    SurfacePoint sp;
    const Mesh& mesh = m_scene.meshes[hit.geom];
    const InstanceXf& xf = m_xf[hit.inst];
    const uint32_t i0 = mesh.indices[size_t(hit.prim) * 3 + 0];
    const uint32_t i1 = mesh.indices[size_t(hit.prim) * 3 + 1];
    const uint32_t i2 = mesh.indices[size_t(hit.prim) * 3 + 2];
    const float u = hit.u, v = hit.v;
    sp.material = mesh.material;

    // Position from the world-space vertices (not o + t d), transformed and blended in double
    // with one final rounding: interpolating float world vertices much larger than the point (a
    // big triangle passing near the origin) cancels catastrophically and leaves the point
    // thousands of ulps off the surface, beyond any ulp-scaled ray offset
    // (docs/numerical-stability.md, StressSelfIntersection.TiltedQuadThroughOrigin*).
    const Mat4d& world = m_scene.instances[hit.inst].world_from_object;
    const Vec3d w0 = world.apply_point(Vec3d(mesh.positions[i0]));
    const Vec3d w1 = world.apply_point(Vec3d(mesh.positions[i1]));
    const Vec3d w2 = world.apply_point(Vec3d(mesh.positions[i2]));
    const double ud = u, vd = v, wd = 1.0 - ud - vd;
    sp.p = Vec3f(w0 * wd + w1 * ud + w2 * vd);
    sp.p_shadow = sp.p;
    // The triangle tests (Woop et al. 2013 in float, Embree's) form v_i - o: their t error is a
    // few ulps of the vertices' coordinates, which on a large triangle near the world origin
    // dwarf ulp(|p|) (ray_offset.h).
    sp.offset_scale = float(std::max({max_abs(w0), max_abs(w1), max_abs(w2)}));
    const Vec3f p0(w0), p1(w1), p2(w2);
    if (!mesh.normals.empty()) {
        // Shadow terminator (Hanika, "Hacking the Shadow Terminator", Ray Tracing Gems II, 2021):
        // with smooth normals on a coarse mesh, points near the terminator see the light by N.L but
        // the flat triangle is shadowed by its neighbours, giving blocky shadows. Lift the shadow
        // origin onto the tangent planes of the vertex normals, blended barycentrically. Done in
        // object space, where the planes are exact, then transformed (affine maps keep planes).
        const Vec3d a(mesh.positions[i0]), b(mesh.positions[i1]), c(mesh.positions[i2]);
        const Vec3d po = a * wd + b * ud + c * vd;
        auto lift = [&](const Vec3d& pv, const Vec3f& nv) {
            const Vec3d n(nv);
            return n * std::min(0.0, dot(po - pv, n));
        };
        const Vec3d delta = lift(a, mesh.normals[i0]) * wd + lift(b, mesh.normals[i1]) * ud + lift(c, mesh.normals[i2]) * vd;
        if (delta != Vec3d(0.0) && std::isfinite(delta.x) && std::isfinite(delta.y) && std::isfinite(delta.z))
            sp.p_shadow = Vec3f(world.apply_point(po - delta));
    }
    Vec3f ng = Vec3f(normalize(cross(w1 - w0, w2 - w0)));  // in double: no cancellation far from the origin
    if (!(ng != Vec3f(0.f)) || !is_finite(ng)) ng = normalize(-ray.dir);  // degenerate triangle: face the ray
    sp.ng = ng;

    // Texture and vertex-color inputs: skipped when nothing in the scene varies over a surface.
    if constexpr (kAttributes) {
        const bool uvs = m_needs_uv[mesh.material] != 0;
        if (uvs && !mesh.uv0.empty()) sp.uv[0] = interpolate(mesh.uv0, i0, i1, i2, u, v);
        if (uvs && !mesh.uv1.empty()) sp.uv[1] = interpolate(mesh.uv1, i0, i1, i2, u, v);
        if (!mesh.colors.empty()) sp.color = interpolate(mesh.colors, i0, i1, i2, u, v);

        // Texture footprint (Akenine-Moeller et al. 2019, ray cones): the cone's width at the hit,
        // stretched by 1/|cos| on the surface, converted to UV units by sqrt(uv area / world area)
        // of the triangle (its UV parameterisation's mean scale). Isotropic: no anisotropic filtering.
        const float width = cone.width_at(hit.t);
        if (width > 0.f) {
            const float cos_theta = std::max(std::abs(dot(ng, ray.dir)), 1e-3f);
            sp.footprint = width / cos_theta;
            const float world_area = uvs ? length(cross(p1 - p0, p2 - p0)) : 0.f;
            auto footprint = [&](const std::vector<Vec2f>& uvs) {
                const Vec2f a = uvs[i0], b = uvs[i1], c = uvs[i2];
                const float uv_area = std::abs((b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y));
                if (!(uv_area > 0.f) || !(world_area > 0.f)) return -kInfinity;
                const float lod = std::log2(width / cos_theta) + 0.5f * std::log2(uv_area / world_area);
                return std::isfinite(lod) ? lod : -kInfinity;
            };
            if (uvs && !mesh.uv0.empty()) sp.uv_lod[0] = footprint(mesh.uv0);
            if (uvs && !mesh.uv1.empty()) sp.uv_lod[1] = footprint(mesh.uv1);
        }
    }

    // Shading normal: interpolated vertex normals, then the normal map.
    Vec3f ns = ng;
    if (!mesh.normals.empty()) {
        Vec3f n = normalize(xf_normal(xf.n, interpolate(mesh.normals, i0, i1, i2, u, v)));
        if (n != Vec3f(0.f) && is_finite(n)) ns = n;
    }
    sp.nc = ns;
    const Material& mat = m_scene.materials[mesh.material];
    // The layers that read the texture-space frame: anisotropy's direction, the coat's normal map.
    const bool layered = mat.model == MaterialModel::GltfPbr && mat.layered() &&
                         (mat.anisotropy_strength > 0.f || mat.clearcoat_normal_texture.valid());
    if (kAttributes && !mesh.tangents.empty() && mat.model == MaterialModel::GltfPbr &&
        (mat.normal_texture.valid() || layered)) {
        // The texture-space frame: the tangent Gram-Schmidt'ed against the interpolated normal.
        Vec4f t4 = interpolate(mesh.tangents, i0, i1, i2, u, v);
        Vec3f t = xf_vector(xf.m, t4.xyz());
        t = normalize(t - ns * dot(ns, t));
        if (t != Vec3f(0.f) && is_finite(t)) {
            const Vec3f b = cross(ns, t) * (t4.w < 0.f ? -1.f : 1.f);
            auto mapped_normal = [&](const TextureRef& ref) {
                const Vec4f tex = lookup(m_scene, ref, sp.uv, sp.uv_lod);
                const float s = ref.scale;
                const Vec3f m{(tex.x * 2.f - 1.f) * s, (tex.y * 2.f - 1.f) * s, tex.z * 2.f - 1.f};
                const Vec3f mapped = normalize(t * m.x + b * m.y + ns * m.z);
                return mapped != Vec3f(0.f) && is_finite(mapped) ? mapped : ns;
            };
            if (layered) {
                if (mat.clearcoat_normal_texture.valid()) sp.nc = mapped_normal(mat.clearcoat_normal_texture);
                sp.tangent = t;
                sp.bitangent = b;
            }
            if (mat.normal_texture.valid()) ns = mapped_normal(mat.normal_texture);
        }
    }
    sp.ns = ns;
    return sp;
}

template <bool kAttributes>
SurfacePoint SceneView::sphere_surface(const Ray& ray, const Hit& hit, const RayCone& cone) const {
    const Sphere& sphere = m_scene.sphere_of(hit.geom);
    SurfacePoint sp;
    sp.material = sphere.material;
    // o + t d carries the error of t; re-project it onto the sphere in double (pbrt-v4,
    // Sphere::Intersect), so the point's error is a few ulps of its magnitude whatever the ray.
    const Vec3d o(ray.org), d(ray.dir);
    const Vec3d hit_d = o + d * double(hit.t);
    Vec3d n = hit_d - sphere.center;
    const double len = length(n);
    n = len > 0.0 ? n / len : -d;
    sp.p = Vec3f(sphere.center + n * sphere.radius);
    sp.p_shadow = sp.p;
    // sphere_roots forms o - c in double and solves the quadratic in float in units of the radius:
    // its t error near the surface is a few ulps of r, whatever |c| (a large sphere grazing the
    // world origin has hit points much smaller than r).
    sp.offset_scale = float(sphere.radius);
    sp.ng = sp.ns = sp.nc = normalize(Vec3f(n));
    if constexpr (!kAttributes) return sp;
    const bool uvs = m_needs_uv[sphere.material] != 0;
    if (uvs) {
        // Longitude about +Y and colatitude from the +Y pole (scene.h: Sphere).
        const double u = std::atan2(n.x, n.z) / (2.0 * kPiD) + 0.5;
        const double v = std::acos(std::clamp(n.y, -1.0, 1.0)) / kPiD;
        sp.uv[0] = sp.uv[1] = Vec2f{float(u), float(v)};
    }
    const float width = cone.width_at(hit.t);
    if (width > 0.f) {
        const float cos_theta = std::max(std::abs(dot(sp.ng, ray.dir)), 1e-3f);
        sp.footprint = width / cos_theta;
        if (!uvs) return sp;
        // One UV unit spans 2 pi r sin(theta) (u) by pi r (v) world units: mean scale
        // sqrt(1 / (2 pi^2 r^2 sin(theta))), sin(theta) clamped near the poles.
        const double sin_theta = std::max(std::sqrt(std::max(0.0, 1.0 - n.y * n.y)), 1e-3);
        const double area = 2.0 * kPiD * kPiD * sphere.radius * sphere.radius * sin_theta;
        const float lod = std::log2(width / cos_theta) - float(0.5 * std::log2(area));
        sp.uv_lod[0] = sp.uv_lod[1] = std::isfinite(lod) ? lod : -kInfinity;
    }
    return sp;
}

template <bool kAttributes>
SurfacePoint SceneView::quadric_surface(const Ray& ray, const Hit& hit, const RayCone& cone) const {
    const Quadric& quadric = m_scene.quadric_of(hit.geom);
    SurfacePoint sp;
    sp.material = quadric.material;
    // o + t d moved onto the face the ray crossed (Hit::prim) in double (quadric_point), as for
    // spheres; its UVs only where the material reads a texture.
    const bool uvs = kAttributes && m_needs_uv[quadric.material] != 0;
    const QuadricPoint qp =
        quadric_point(quadric, Vec3d(ray.org) + Vec3d(ray.dir) * double(hit.t), int(hit.prim), uvs);
    sp.p = Vec3f(qp.p);
    sp.p_shadow = sp.p;
    // quadric_crossings solves in double about the quadric's centre: its t error is far below a
    // float ulp of the point, so the offset unit is the point's own; as for planes, 2^-26 of the
    // magnitude of the shape's origin keeps it from vanishing next to the world origin.
    sp.offset_scale = float(max_abs(quadric.world_from_object.apply_point({0.0, 0.0, 0.0}))) * 0x1p-26f;
    sp.ng = sp.ns = sp.nc = Vec3f(qp.n);
    if constexpr (!kAttributes) return sp;
    if (uvs) sp.uv[0] = sp.uv[1] = Vec2f{float(qp.u), float(qp.v)};
    const float width = cone.width_at(hit.t);
    if (width > 0.f) {
        const float cos_theta = std::max(std::abs(dot(sp.ng, ray.dir)), 1e-3f);
        sp.footprint = width / cos_theta;
        if (!uvs) return sp;
        const float lod = std::log2(sp.footprint) - float(0.5 * std::log2(qp.uv_area));
        sp.uv_lod[0] = sp.uv_lod[1] = std::isfinite(lod) ? lod : -kInfinity;
    }
    return sp;
}

template <bool kAttributes>
SurfacePoint SceneView::plane_surface(const Ray& ray, const Hit& hit, const RayCone& cone) const {
    const Plane& plane = m_scene.plane_of(hit.geom);
    SurfacePoint sp;
    sp.material = plane.material;
    // o + t d, projected back onto the plane in double.
    const Vec3d o(ray.org), d(ray.dir);
    Vec3d p = o + d * double(hit.t);
    p = p - plane.normal * dot(plane.normal, p - plane.point);
    sp.p = Vec3f(p);
    sp.p_shadow = sp.p;
    // intersect_plane computes dot(normal, point - o) in double: its error, at most ~8 double ulps
    // of max|point|, stays below a quarter of the 4-ulp float offset of 2^-26 max|point|, so only a
    // plane defined by a point ~1e8 times farther out than the hit moves the unit.
    sp.offset_scale = float(max_abs(plane.point)) * 0x1p-26f;
    sp.ng = sp.ns = sp.nc = Vec3f(plane.normal);
    if constexpr (!kAttributes) return sp;
    const bool uvs = m_needs_uv[plane.material] != 0;
    if (uvs) {
        const Vec3d rel = p - plane.point;
        const Vec3d v_axis = cross(plane.normal, plane.u_axis);
        sp.uv[0] = sp.uv[1] = Vec2f{float(dot(rel, plane.u_axis)), float(dot(rel, v_axis))};
    }
    const float width = cone.width_at(hit.t);
    if (width > 0.f) {
        // UV units are world units.
        const float cos_theta = std::max(std::abs(dot(sp.ng, ray.dir)), 1e-3f);
        sp.footprint = width / cos_theta;
        if (!uvs) return sp;
        const float lod = std::log2(sp.footprint);
        sp.uv_lod[0] = sp.uv_lod[1] = std::isfinite(lod) ? lod : -kInfinity;
    }
    return sp;
}

PbrSample SceneView::material_inputs(const Material& m, const SurfacePoint& sp) const {
    PbrSample s;
    Vec4f bc = lookup(m_scene, m.base_color_texture, sp.uv, sp.uv_lod);
    s.base_color = {m.base_color.x * bc.x * sp.color.x, m.base_color.y * bc.y * sp.color.y,
                    m.base_color.z * bc.z * sp.color.z, m.base_color.w * bc.w * sp.color.w};
    Vec4f mr = lookup(m_scene, m.metallic_roughness_texture, sp.uv, sp.uv_lod);
    s.metallic = std::clamp(m.metallic * mr.z, 0.f, 1.f);
    s.roughness = std::clamp(m.roughness * mr.y, 0.f, 1.f);
    s.transmission = std::clamp(m.transmission * lookup(m_scene, m.transmission_texture, sp.uv, sp.uv_lod).x, 0.f, 1.f);
    if (m.occlusion_texture.valid()) {
        float occ = lookup(m_scene, m.occlusion_texture, sp.uv, sp.uv_lod).x;
        s.occlusion = 1.f + m.occlusion_texture.scale * (occ - 1.f);
    }
    Vec4f em = lookup(m_scene, m.emissive_texture, sp.uv, sp.uv_lod);
    s.emissive = m.emissive * em.xyz() * m.emissive_strength;
    s.specular = m.specular * lookup(m_scene, m.specular_texture, sp.uv, sp.uv_lod).w;
    s.specular_color = m.specular_color * lookup(m_scene, m.specular_color_texture, sp.uv, sp.uv_lod).xyz();
    if (m.specular_glossiness)
        apply_specular_glossiness(m, lookup(m_scene, m.specular_glossiness_texture, sp.uv, sp.uv_lod), s);
    if (m.layered()) layer_inputs(m, sp, s);
    return s;
}

void SceneView::layer_inputs(const Material& m, const SurfacePoint& sp, PbrSample& s) const {
    auto channel = [&](const TextureRef& ref, int c) { return lookup(m_scene, ref, sp.uv, sp.uv_lod)[c]; };
    s.clearcoat = m.clearcoat * channel(m.clearcoat_texture, 0);
    s.clearcoat_roughness = m.clearcoat_roughness * channel(m.clearcoat_roughness_texture, 1);
    s.sheen_color = m.sheen_color * lookup(m_scene, m.sheen_color_texture, sp.uv, sp.uv_lod).xyz();
    s.sheen_roughness = m.sheen_roughness * channel(m.sheen_roughness_texture, 3);
    s.iridescence = m.iridescence * channel(m.iridescence_texture, 0);
    // Without a thickness texture the film is iridescenceThicknessMaximum thick (texel 1).
    const float g = channel(m.iridescence_thickness_texture, 1);
    s.iridescence_thickness = m.iridescence_thickness_min + (m.iridescence_thickness_max - m.iridescence_thickness_min) * g;
    // KHR_materials_anisotropy: the texture's direction (RG from [0, 1] to [-1, 1], (1, 0) without
    // one) rotated by anisotropyRotation; its B channel scales the strength.
    const float cos_r = std::cos(m.anisotropy_rotation), sin_r = std::sin(m.anisotropy_rotation);
    Vec2f d{1.f, 0.f};
    float strength = m.anisotropy_strength;
    if (m.anisotropy_texture.valid()) {
        const Vec4f a = lookup(m_scene, m.anisotropy_texture, sp.uv, sp.uv_lod);
        const Vec2f t{a.x * 2.f - 1.f, a.y * 2.f - 1.f};
        const float len = std::sqrt(t.x * t.x + t.y * t.y);
        if (len > 0.f) d = {t.x / len, t.y / len};
        strength *= a.z;
    }
    s.anisotropy = strength;
    s.anisotropy_direction = {cos_r * d.x - sin_r * d.y, sin_r * d.x + cos_r * d.y};
    s.diffuse_transmission = m.diffuse_transmission * channel(m.diffuse_transmission_texture, 3);
    s.diffuse_transmission_color =
        m.diffuse_transmission_color * lookup(m_scene, m.diffuse_transmission_color_texture, sp.uv, sp.uv_lod).xyz();
}

WhittedCoeffs SceneView::layered_coefficients(const SurfacePoint& sp, const LayerFrame& f, LayerCoeffs& layers) const {
    const Material& m = m_scene.materials[sp.material];
    return map_layered(m, material_inputs(m, sp), f, m_mapping, layers);
}

WhittedCoeffs SceneView::coefficients(const SurfacePoint& sp) const {
    const Material& m = m_scene.materials[sp.material];
    if (m.model == MaterialModel::Classic) {
        WhittedCoeffs c = m.classic;
        // The scene file's color texture (checker or image) and vertex colors tint kd and Ka.
        Color tint = sp.color.xyz();
        if (m.classic_color_texture.valid())
            tint *= lookup(m_scene, m.classic_color_texture, sp.uv, sp.uv_lod, sp.p, sp.ng, sp.footprint).xyz();
        c.kd *= tint;
        c.ka *= tint;
        return c;
    }
    return map_gltf_material(m, material_inputs(m, sp), m_mapping);
}

Color SceneView::shadow_kt(const Material& m, const Ray& ray, const Hit& hit) const {
    const std::optional<Color>& constant = m_constant_shadow_kt[m_scene.geom_material(hit.geom)];
    return constant ? *constant : transmitted_light(m, surface(ray, hit));
}

Color SceneView::transmitted_light(const Material& m, const SurfacePoint& sp) const {
    const PbrSample s = material_inputs(m, sp);
    if (!(m.diffuse_transmission > 0.f)) return map_gltf_material(m, s, m_mapping).kt;
    // KHR_materials_diffuse_transmission: what the surface lets through diffusely also reaches
    // the far side of a shadow ray, as a filter (its direction is not followed).
    Color kdt;
    const WhittedCoeffs c = map_layered_base(m, s, m_mapping, 1.f, kdt);
    return c.kt + kdt;
}

float SceneView::alpha_at(const Material& m, const Hit& hit) const {
    const Mesh& mesh = m_scene.meshes[hit.geom];
    const uint32_t i0 = mesh.indices[size_t(hit.prim) * 3 + 0];
    const uint32_t i1 = mesh.indices[size_t(hit.prim) * 3 + 1];
    const uint32_t i2 = mesh.indices[size_t(hit.prim) * 3 + 2];
    Vec2f uv[2];
    if (!mesh.uv0.empty()) uv[0] = interpolate(mesh.uv0, i0, i1, i2, hit.u, hit.v);
    if (!mesh.uv1.empty()) uv[1] = interpolate(mesh.uv1, i0, i1, i2, hit.u, hit.v);
    float a = m.base_color.w * lookup(m_scene, m.base_color_texture, uv, kNoFootprint).w;
    if (!mesh.colors.empty()) a *= interpolate(mesh.colors, i0, i1, i2, hit.u, hit.v).w;
    return std::clamp(a, 0.f, 1.f);
}

bool SceneView::accept(const Ray& ray, const Hit& hit, RayKind kind) const {
    if (m_scene.geom_kind(hit.geom) != GeomKind::Mesh) return true;  // analytic: no cut-outs, two-sided
    const Material& m = m_scene.materials[m_scene.meshes[hit.geom].material];
    if (m.model != MaterialModel::GltfPbr) return true;
    if (m.alpha_mode == AlphaMode::Mask && alpha_at(m, hit) < m.alpha_cutoff) return false;
    // Back faces of single-sided materials are culled for camera rays only: culling secondary or
    // shadow rays would let light leak through closed meshes.
    if (kind == RayKind::Camera && !m.double_sided && dot(world_geometric_normal(hit), ray.dir) > 0.f) return false;
    return true;
}

Color SceneView::transmittance(const Ray& ray, const Hit& hit) const {
    const Material& m = m_scene.materials[m_scene.geom_material(hit.geom)];
    if (m.model == MaterialModel::Classic) return m.classic.kt;
    if (m_scene.geom_kind(hit.geom) != GeomKind::Mesh) {
        // glTF material on an analytic primitive: Kt at the point (no alpha coverage).
        return shadow_kt(m, ray, hit);
    }
    float coverage = 1.f;
    if (m.alpha_mode == AlphaMode::Mask) {
        if (alpha_at(m, hit) < m.alpha_cutoff) return Color(1.f);
    } else if (m.alpha_mode == AlphaMode::Blend) {
        coverage = alpha_at(m, hit);
    }
    Color kt(0.f);
    if (m.transmission > 0.f || m.diffuse_transmission > 0.f) kt = shadow_kt(m, ray, hit);
    // BLEND: the uncovered fraction passes untouched, the covered part passes through Kt.
    return Color(1.f - coverage) + kt * coverage;
}

template SurfacePoint SceneView::surface<true>(const Ray&, const Hit&, const RayCone&) const;
template SurfacePoint SceneView::surface<false>(const Ray&, const Hit&, const RayCone&) const;

}  // namespace whitted
