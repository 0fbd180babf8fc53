// Scene analysis at load: per-material features, their OR over the scene, and which lights can
// reach which objects (range window, spot cone). See scene_analysis.h for the contracts.
#include "shading/scene_analysis.h"
#include "shading/environment_map.h"

#include <algorithm>
#include <cmath>

namespace whitted {

namespace {

bool any_texture(const Material& m) {
    for (const TextureRef* r : m.texture_slots())
        if (r->valid()) return true;
    return false;
}

bool nonzero(const Vec4f& v) { return v.x > 0.f || v.y > 0.f || v.z > 0.f; }

/// The flags of one material, before `used` and `vertex_colors` (which depend on the geometry).
MaterialFeatures material_features(const Material& m, const MappingOptions& mapping) {
    MaterialFeatures f;
    f.textured = any_texture(m);
    f.constant = map_material_constant(m, mapping);
    f.constant_alpha = std::clamp(m.base_color.w, 0.f, 1.f);
    if (m.model == MaterialModel::Classic) {
        // Whitted's (1980) coefficients; a colour texture or vertex colors only tint kd and ka.
        const WhittedCoeffs& c = m.classic;
        f.diffuse = !is_black(c.kd);
        f.highlight = !is_black(c.ks);
        f.mirror = !is_black(c.kr);
        f.transmission = !is_black(c.kt);
        f.emissive = !is_black(c.emission);
        f.volume = f.transmission && !c.thin && !is_black(c.absorption);
        return f;
    }
    f.alpha_mask = m.alpha_mode == AlphaMode::Mask;
    f.alpha_blend = m.alpha_mode == AlphaMode::Blend;
    f.single_sided = !m.double_sided;
    if (m.unlit) {
        // map_gltf_material: emission = base colour, nothing else.
        f.unlit = true;
        f.emissive = nonzero(m.base_color);
        return f;
    }
    // Textures only scale factors down (texels are in [0, 1]), except that a metallic or
    // transmission texture can lower a factor of 1, which frees kd. Conservative otherwise.
    const bool base = nonzero(m.base_color);
    const bool metal_below_one = m.metallic < 1.f || m.metallic_roughness_texture.valid();
    const bool transmission_below_one = m.transmission < 1.f || m.transmission_texture.valid();
    f.diffuse = base && metal_below_one && transmission_below_one;
    f.transmission = base && metal_below_one && m.transmission > 0.f;
    f.highlight = !is_black(f.constant.ks) || f.textured;
    // kr = F0 * fade(roughness): roughness = factor x texture <= factor.
    const bool smooth_enough = m.metallic_roughness_texture.valid()
                                   ? mapping.mirror_roughness_cutoff > 0.f
                                   : mirror_fade(std::clamp(m.roughness, 0.f, 1.f), mapping.mirror_roughness_cutoff) > 0.f;
    f.mirror = smooth_enough && (!is_black(f.constant.ks) || f.textured);
    f.emissive = !is_black(m.emissive) && m.emissive_strength > 0.f;
    f.volume = f.transmission && m.has_volume && m.thickness > 0.f && !is_black(f.constant.absorption);
    if (m.layered()) {
        // Evaluated per hit and view (layered_model.h). Mirror rays: a smooth enough coat's own,
        // and a thin film's (its Fresnel is not 0 where F0 is).
        f.layered = true;
        f.highlight = true;
        const bool coat_mirror = m.clearcoat > 0.f && (m.clearcoat_roughness_texture.valid()
                                                           ? mapping.mirror_roughness_cutoff > 0.f
                                                           : mirror_fade(std::clamp(m.clearcoat_roughness, 0.f, 1.f),
                                                                         mapping.mirror_roughness_cutoff) > 0.f);
        f.mirror |= coat_mirror || (m.iridescence > 0.f && smooth_enough);
        f.diffuse |= m.diffuse_transmission > 0.f;
        // Diffuse transmission lets shadow rays through (SceneView::transmittance).
        f.transmission |= m.diffuse_transmission > 0.f;
    }
    return f;
}

/// The prefiltered environment levels the glossy term of a material can read: classic materials
/// have constant kg and roughness; glTF ones roughness = factor x texture (<= factor), and a
/// textured one may have kg > 0 where its factors give 0.
uint32_t glossy_levels(const Material& m, const MaterialFeatures& f) {
    if (m.model == MaterialModel::Classic)
        return is_black(f.constant.kg) ? 0u : prefilter_levels_read(f.constant.roughness, f.constant.roughness);
    if (m.unlit || (is_black(f.constant.kg) && !f.textured && !f.layered)) return 0u;
    const float r = std::clamp(m.roughness, 0.f, 1.f);
    const float lo = m.metallic_roughness_texture.valid() ? 0.f : r;
    // Anisotropy reads sqrt(sqrt(alpha_t alpha_b)) in [r, sqrt(r)] (alpha_t <= 1, alpha_b = r^2).
    uint32_t levels = prefilter_levels_read(lo, m.anisotropy_strength > 0.f ? std::sqrt(r) : r);
    if (m.clearcoat > 0.f) {
        // The coat's glossy term: clearcoat roughness = factor x texture <= factor.
        const float rc = std::clamp(m.clearcoat_roughness, 0.f, 1.f);
        levels |= prefilter_levels_read(m.clearcoat_roughness_texture.valid() ? 0.f : rc, rc);
    }
    return levels;
}

/// Smallest distance from p to the box b (0 inside).
double distance_to_box(const Vec3d& p, const Bounds3d& b) {
    const Vec3d d = vmax(vmax(b.lo - p, p - b.hi), Vec3d(0.0));
    return length(d);
}

/// Relative and absolute slack of the reach tests: the per-point tests run in float on points
/// interpolated in float, so a light is culled only with this much room to spare.
constexpr double kReachRelative = 1e-3;
constexpr double kReachAngle = 1e-3;  ///< radians

/// True when `light` can deliver non-zero intensity somewhere inside the bounding box `b` of an
/// object (the object lies within the box). Counts the reason when it cannot.
bool reaches_box(const Light& light, const Bounds3d& b, LightReach& reach) {
    if (light.type == LightType::Directional || b.empty()) return true;
    const Vec3d pos = light.position;
    const double scale = std::max({length(pos), length(b.lo), length(b.hi), 1.0});
    const double slack = kReachRelative * scale;
    // glTF range: the window (1 - (d/r)^4)^2 is exactly 0 at d >= r (InverseSquare only).
    if (light.attenuation == Attenuation::InverseSquare && light.range > 0.f &&
        distance_to_box(pos, b) > double(light.range) * (1.0 + kReachRelative) + slack) {
        ++reach.culled_range;
        return false;
    }
    // Spot cone: the falloff is exactly 0 at or beyond the outer angle. The box's bounding
    // sphere seen from the light covers the angles [theta - alpha, theta + alpha].
    if (light.type == LightType::Spot && double(light.outer_cone) + kReachAngle < kPiD / 2) {
        const Vec3d c = b.center();
        const double radius = 0.5 * length(b.diagonal()) + slack;
        const Vec3d v = c - pos;
        const double dist = length(v);
        if (dist > radius) {
            const double cos_theta = std::clamp(dot(normalize(Vec3d(light.direction)), v / dist), -1.0, 1.0);
            const double theta = std::acos(cos_theta), alpha = std::asin(std::min(1.0, radius / dist));
            if (theta - alpha > double(light.outer_cone) + kReachAngle) {
                ++reach.culled_cone;
                return false;
            }
        }
    }
    return true;
}

/// Same for an infinite plane: only the range window can exclude it.
bool reaches_plane(const Light& light, const Plane& plane, LightReach& reach) {
    if (light.type == LightType::Directional) return true;
    if (light.attenuation == Attenuation::InverseSquare && light.range > 0.f) {
        const Vec3d pos = light.position;
        const double d = std::abs(dot(normalize(plane.normal), pos - plane.point));
        const double scale = std::max({length(pos), length(plane.point), 1.0});
        if (d > double(light.range) * (1.0 + kReachRelative) + kReachRelative * scale) {
            ++reach.culled_range;
            return false;
        }
    }
    return true;
}

template <typename T, typename Alloc>
size_t bytes_of(const std::vector<T, Alloc>& v) {
    return v.size() * sizeof(T);
}

/// A PaddedVector with its zeroed tail (Mesh::positions).
template <typename T>
size_t bytes_of(const PaddedVector<T>& v) {
    return v.empty() ? 0 : v.size() * sizeof(T) + kPaddedVectorTailBytes;
}

}  // namespace

SceneAnalysis analyze_scene(const Scene& scene, const MappingOptions& mapping) {
    SceneAnalysis a;
    a.materials.reserve(scene.materials.size());
    for (const Material& m : scene.materials) a.materials.push_back(material_features(m, mapping));

    // Geometry: which materials are used, with vertex colors, and what the meshes carry.
    auto use = [&](uint32_t material) -> MaterialFeatures* {
        if (material >= a.materials.size()) return nullptr;
        a.materials[material].used = true;
        return &a.materials[material];
    };
    std::vector<bool> mesh_instanced(scene.meshes.size(), false);
    for (const Instance& inst : scene.instances)
        if (inst.mesh < mesh_instanced.size()) mesh_instanced[inst.mesh] = true;
    for (size_t i = 0; i < scene.meshes.size(); ++i) {
        const Mesh& mesh = scene.meshes[i];
        a.scene_bytes += bytes_of(mesh.positions) + bytes_of(mesh.normals) + bytes_of(mesh.tangents) +
                         bytes_of(mesh.uv0) + bytes_of(mesh.uv1) + bytes_of(mesh.colors) + bytes_of(mesh.indices);
        if (!mesh_instanced[i] || mesh.triangle_count() == 0) continue;
        MaterialFeatures* f = use(mesh.material);
        if (f && !mesh.colors.empty()) f->vertex_colors = true;
        a.features.uv |= !mesh.uv0.empty() || !mesh.uv1.empty();
        a.features.tangents |= !mesh.tangents.empty();
    }
    for (const Sphere& s : scene.spheres) use(s.material);
    for (const Quadric& q : scene.quadrics) use(q.material);
    for (const Plane& p : scene.planes) use(p.material);
    a.features.uv |= !scene.spheres.empty() || !scene.quadrics.empty() || !scene.planes.empty();
    for (const Texture& t : scene.textures)
        for (const MipLevel& level : t.levels) a.texture_bytes += bytes_of(level.texels);
    a.triangles = scene.instanced_triangle_count();
    a.spheres = scene.spheres.size();
    a.sphere_bytes = scene.spheres.capacity() * sizeof(Sphere);
    for (const Sphere& sp : scene.spheres)
        if (sp.name.capacity() > std::string().capacity()) a.sphere_bytes += sp.name.capacity() + 1;  // beyond the SSO buffer

    // Per material: varying = evaluated per hit; the OR over the used ones.
    SceneFeatures& s = a.features;
    for (MaterialFeatures& f : a.materials) {
        f.varying = f.textured || f.vertex_colors || f.layered;
        if (f.used) s |= f;
    }
    for (size_t i = 0; i < a.materials.size(); ++i)
        if (a.materials[i].used) a.prefilter_levels |= glossy_levels(scene.materials[i], a.materials[i]);

    // Light reach per object: instances (transformed mesh bounds), spheres, quadrics, planes.
    std::vector<Bounds3d> mesh_bounds(scene.meshes.size());
    for (size_t i = 0; i < scene.meshes.size(); ++i) mesh_bounds[i] = scene.meshes[i].bounds();
    std::vector<Bounds3d> object_bounds;
    object_bounds.reserve(scene.instances.size() + scene.spheres.size() + scene.quadrics.size());
    for (const Instance& inst : scene.instances)
        object_bounds.push_back(transform_bounds(
            inst.world_from_object, inst.mesh < mesh_bounds.size() ? mesh_bounds[inst.mesh] : Bounds3d{}));
    for (const Sphere& sp : scene.spheres) {
        Bounds3d b;
        b.extend(sp.center - Vec3d(sp.radius));
        b.extend(sp.center + Vec3d(sp.radius));
        object_bounds.push_back(b);
    }
    for (const Quadric& q : scene.quadrics) object_bounds.push_back(quadric_bounds(q));
    a.object_count = uint32_t(object_bounds.size() + scene.planes.size());
    a.lights.assign(scene.lights.size(), LightReach{});
    a.light_offsets.reserve(a.object_count + 1);
    a.light_offsets.push_back(0);
    for (uint32_t o = 0; o < a.object_count; ++o) {
        for (uint32_t l = 0; l < scene.lights.size(); ++l) {
            const Light& light = scene.lights[l];
            LightReach& reach = a.lights[l];
            // Non-finite bounds or lights: never culled (the per-point tests decide).
            const bool reached = o < object_bounds.size()
                                     ? (!is_finite(object_bounds[o].lo) || !is_finite(object_bounds[o].hi) ||
                                        !is_finite(light.position) || reaches_box(light, object_bounds[o], reach))
                                     : reaches_plane(light, scene.planes[o - object_bounds.size()], reach);
            if (!reached) continue;
            ++reach.objects_reached;
            a.light_indices.push_back(l);
        }
        a.light_offsets.push_back(uint32_t(a.light_indices.size()));
    }
    return a;
}

}  // namespace whitted
