// SceneView: the render-time view of a Scene. Precomputes per-instance float transforms,
// per-mesh flags and the SceneAnalysis (what the scene uses, which lights reach which object),
// turns a minimal Hit into a SurfacePoint (position, normals, UVs, colors) and evaluates
// materials there. It is also the SurfaceFilter backends consult during traversal.
#pragma once

#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "accel/accelerator.h"
#include "scene/scene.h"
#include "shading/environment_map.h"
#include "shading/layered_model.h"
#include "shading/light_sample.h"
#include "shading/material_mapping.h"
#include "shading/scene_analysis.h"

namespace whitted {

/// A ray cone (Amanatides 1984; Akenine-Moeller et al., "Texture Level of Detail Strategies for
/// Real-Time Ray Tracing", Ray Tracing Gems 2019): the footprint of a ray is `width + spread * t`
/// world units at distance t. {0, 0} = a point sample (textures use their finest level).
struct RayCone {
    float width = 0.f;          ///< footprint width at the ray origin (world units)
    float spread = 0.f;         ///< growth of the width per unit distance (radians, small angle)
    /// Width at distance t along a unit-direction ray.
    float width_at(float t) const { return width + spread * t; }
};

/// Everything the integrator needs about one hit point (world space).
struct SurfacePoint {
    Vec3f p;                    ///< position, interpolated from the triangle's world-space vertices
    Vec3f p_shadow;             ///< shadow-ray origin on the front side: p lifted onto the smooth
                                ///< surface the vertex normals describe (Hanika 2021), = p when flat
    float offset_scale = 0.f;   ///< magnitude of the hit primitive's coordinates, the scale of its
                                ///< intersection test's rounding: ray origins leave p by ulps of
                                ///< max(max|p|, offset_scale) (ray_offset.h). Triangles: the largest
                                ///< |coordinate| of the world-space vertices; spheres: the radius;
                                ///< planes: 2^-26 max|point| (see SceneView::surface)
    Vec3f ng;                   ///< unit geometric normal (front side by winding)
    Vec3f ns;                   ///< unit shading normal (interpolated, normal-mapped), front side
    Vec3f nc;                   ///< unit clearcoat normal (interpolated, clearcoat-normal-mapped), front side
    Vec3f tangent, bitangent;   ///< texture-space frame about the interpolated normal, only for layered
                                ///< materials on meshes with tangents (zero otherwise)
    Vec2f uv[2];                ///< TEXCOORD_0/1 (0 when absent)
    Vec4f color{1.f, 1.f, 1.f, 1.f};  ///< COLOR_0 (1 when absent)
    uint32_t material = 0;
    float uv_lod[2] = {-kInfinity, -kInfinity};  ///< log2 of the footprint's width in UV units per
                                ///< UV set (ray cone / |cos| x sqrt(uv area / world area));
                                ///< -inf = no footprint (point sample, finest MIP level)
    float footprint = 0.f;      ///< the ray cone's width on the surface (world units, / |cos|);
                                ///< 0 = point sample (world-space procedural textures)
};

class SceneView final : public SurfaceFilter {
public:
    SceneView(const Scene& scene, const MappingOptions& mapping);

    /// Derives everything again from the scene after it changed in place (scene_update.h), the
    /// environment map only when the materials now read other prefiltered levels. Returns false
    /// when some geometry's traversal flags (mesh_flags) changed: an accelerator built with the
    /// old ones must be built anew.
    bool update();

    /// Surface data at a hit of unit-direction `ray`; `cone` is the ray's footprint, which
    /// selects texture MIP levels (the default point cone samples the finest level).
    /// kAttributes = false skips what only textures and vertex colors need (UVs, COLOR_0, the
    /// footprint, normal maps): p, p_shadow, ng and ns are the same, uv/color/uv_lod/footprint
    /// keep their defaults. Only valid when no material the hit can use is varying
    /// (SceneAnalysis::features.varying is false). With kAttributes, uv and uv_lod also keep their
    /// defaults when the hit's material reads no texture through UVs (none, or a world-space
    /// checker, which reads p, ng and footprint).
    template <bool kAttributes = true>
    SurfacePoint surface(const Ray& ray, const Hit& hit, const RayCone& cone = {}) const;
    /// Material inputs at a point (factors x textures x vertex color).
    PbrSample material_inputs(const Material& material, const SurfacePoint& sp) const;
    /// Whitted's (1980) coefficients at a point.
    WhittedCoeffs coefficients(const SurfacePoint& sp) const;
    /// A layered material's base coefficients and layers at a point seen in frame `f` (map_layered).
    WhittedCoeffs layered_coefficients(const SurfacePoint& sp, const LayerFrame& f, LayerCoeffs& layers) const;
    const Scene& scene() const { return m_scene; }
    const MappingOptions& mapping() const { return m_mapping; }
    /// What the scene uses, analysed with this view's mapping options.
    const SceneAnalysis& analysis() const { return m_analysis; }
    /// The scene's environment as a filtered map, or null when the scene has none.
    const EnvironmentMap* environment() const { return m_environment.get(); }
    /// The lights that may reach the object hit (SceneAnalysis::lights_of), ascending.
    std::span<const uint32_t> lights_reaching(const Hit& hit) const {
        return m_analysis.lights_of(object_index(m_scene, hit.geom, hit.inst));
    }

    /// sample_light(scene().lights[light], p) of a directional light, the same at every point,
    /// from a table made once; null for the other kinds (the caller samples them at its point).
    const LightSample* directional_sample(uint32_t light) const {
        return m_scene.lights[light].type == LightType::Directional ? &m_directional_samples[light] : nullptr;
    }

    // SurfaceFilter
    bool accept(const Ray& ray, const Hit& hit, RayKind kind) const override;
    Color transmittance(const Ray& ray, const Hit& hit) const override;
    uint32_t mesh_flags(uint32_t geom) const override { return m_mesh_flags[geom]; }

private:
    /// Everything the view holds, from the scene (the environment map when missing or stale).
    void derive();
    /// What a shadow ray crossing a glTF surface at sp keeps: kt, plus the diffuse transmission's kdt.
    Color transmitted_light(const Material& m, const SurfacePoint& sp) const;
    /// transmitted_light at a shadow ray's crossing, from the per-material table where constant.
    Color shadow_kt(const Material& m, const Ray& ray, const Hit& hit) const;
    /// The layered extensions' inputs at a point (factors x texture channels) into `s`.
    void layer_inputs(const Material& m, const SurfacePoint& sp, PbrSample& s) const;
    /// Coverage alpha at a hit (base color alpha x texture x vertex alpha), UV0/UV1 interpolated.
    float alpha_at(const Material& m, const Hit& hit) const;
    Vec3f world_geometric_normal(const Hit& hit) const;
    // Each kind's point, out of line: surface() returns each one in place (inlined, its own `sp`
    // was copied into surface()'s result, a copy that read back narrower stores and stalled).
    template <bool kAttributes>
    [[gnu::noinline]] SurfacePoint mesh_surface(const Ray& ray, const Hit& hit, const RayCone& cone) const;
    template <bool kAttributes>
    [[gnu::noinline]] SurfacePoint sphere_surface(const Ray& ray, const Hit& hit, const RayCone& cone) const;
    template <bool kAttributes>
    [[gnu::noinline]] SurfacePoint plane_surface(const Ray& ray, const Hit& hit, const RayCone& cone) const;
    template <bool kAttributes>
    [[gnu::noinline]] SurfacePoint quadric_surface(const Ray& ray, const Hit& hit, const RayCone& cone) const;

    struct InstanceXf {
        float m[12];            ///< world_from_object, row-major 3x4
        float n[9];             ///< normal matrix (inverse transpose of the 3x3 part), row-major
    };
    const Scene& m_scene;
    MappingOptions m_mapping;
    std::vector<InstanceXf> m_xf;
    std::vector<uint32_t> m_mesh_flags;
    std::vector<uint8_t> m_needs_uv;  ///< per material: some texture is read through UVs (not a
                                      ///< world-space checker); 0 = surface() skips UVs and MIP levels
    SceneAnalysis m_analysis;
    std::shared_ptr<const EnvironmentMap> m_environment;  ///< built from scene.environment
    std::vector<std::optional<Color>> m_constant_shadow_kt;  ///< per material: transmitted_light where constant
    std::vector<LightSample> m_directional_samples;  ///< per light: sample_light() of a directional one
};

extern template SurfacePoint SceneView::surface<true>(const Ray&, const Hit&, const RayCone&) const;
extern template SurfacePoint SceneView::surface<false>(const Ray&, const Hit&, const RayCone&) const;

}  // namespace whitted
