// SceneAnalysis: what a scene uses, computed once after loading, so the renderer pays only for
// the features a scene needs ("skip what a scene does not need", docs/performance.md).
//
// How to use:
//   const SceneAnalysis a = analyze_scene(scene, mapping);   // O(triangles) once
//   if (!a.features.transmission) ...                         // opaque scene: no transmittance path
//   for (uint32_t l : a.lights_of(object)) ...                // lights that can reach an object
//
// Every flag is conservative: false means the term is exactly zero at every point of every
// surface (so skipping it cannot change the image); true means it may be non-zero somewhere.
// Light reach uses bounds with a safety margin, so a light is only culled for an object when the
// per-point tests (glTF range window, spot cone) would give exactly zero everywhere on it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "scene/scene.h"
#include "shading/material_mapping.h"

namespace whitted {

/// The feature flags a material has and a scene ORs together (operator|=, kept next to the
/// flags so that a new flag is ORed where it is declared).
struct FeatureFlags {
    bool diffuse = false;         ///< kd may be > 0
    bool highlight = false;       ///< ks may be > 0 (Phong-Blinn highlight)
    bool mirror = false;          ///< kr may be > 0: reflection rays
    bool transmission = false;    ///< kt may be > 0: refraction rays, coloured shadows
    bool emissive = false;        ///< emission may be > 0
    bool unlit = false;           ///< KHR_materials_unlit: the colour is the answer
    bool textured = false;        ///< references a texture (any slot, normal maps included)
    bool vertex_colors = false;   ///< a mesh using it has COLOR_0
    bool alpha_mask = false;      ///< alpha MASK cut-outs (filters in traversal)
    bool alpha_blend = false;     ///< alpha BLEND: rays behind, partial shadows
    bool volume = false;          ///< Beer-Lambert absorption inside (KHR_materials_volume)
    bool single_sided = false;    ///< back faces culled for camera rays (filters in traversal)
    bool layered = false;         ///< a layered extension (clearcoat, sheen, ...): the layered kernel
    /// Coefficients depend on the point (textures or vertex colors): evaluated per hit. Otherwise
    /// MaterialFeatures::constant holds them for every point.
    bool varying = false;

    FeatureFlags& operator|=(const FeatureFlags& o) {
        diffuse |= o.diffuse;
        highlight |= o.highlight;
        mirror |= o.mirror;
        transmission |= o.transmission;
        emissive |= o.emissive;
        unlit |= o.unlit;
        textured |= o.textured;
        vertex_colors |= o.vertex_colors;
        alpha_mask |= o.alpha_mask;
        alpha_blend |= o.alpha_blend;
        volume |= o.volume;
        single_sided |= o.single_sided;
        layered |= o.layered;
        varying |= o.varying;
        return *this;
    }
};

/// What one material can produce anywhere on the surfaces that use it.
struct MaterialFeatures : FeatureFlags {
    bool used = false;            ///< some mesh, sphere or plane uses it
    WhittedCoeffs constant;       ///< the coefficients when !varying (also: at the factors alone)
    float constant_alpha = 1.f;   ///< coverage alpha when !varying (base colour alpha, clamped)
};

/// The OR of MaterialFeatures over the used materials, and what the geometry carries.
struct SceneFeatures : FeatureFlags {
    bool uv = false;              ///< some mesh has TEXCOORD_0/1 (or spheres/quadrics/planes: always parametrised)
    bool tangents = false;        ///< some mesh has tangents
    /// Secondary rays can exist: mirrors, transmission or alpha blend.
    bool recursive() const { return mirror || transmission || alpha_blend; }
    /// Shadow rays only ever need "blocked or not" (no transmittance products).
    bool opaque() const { return !transmission && !alpha_blend; }
};

/// How far one light reaches over the scene's objects (instances, spheres, planes).
struct LightReach {
    uint32_t objects_reached = 0; ///< objects the light may illuminate
    uint32_t culled_range = 0;    ///< objects entirely beyond the glTF `range`
    uint32_t culled_cone = 0;     ///< objects entirely outside the spot cone
};

struct SceneAnalysis {
    std::vector<MaterialFeatures> materials;  ///< per Scene::materials
    SceneFeatures features;
    std::vector<LightReach> lights;           ///< per Scene::lights
    /// Objects: instances [0, I), spheres [I, I + S), quadrics [I + S, I + S + Q), then planes
    /// (object_index()).
    uint32_t object_count = 0;
    std::vector<uint32_t> light_offsets;      ///< object o's lights: light_indices[offsets[o], offsets[o+1])
    std::vector<uint32_t> light_indices;      ///< ascending light indices per object
    size_t scene_bytes = 0;                   ///< mesh data (positions, normals, tangents, UVs, colors, indices)
    size_t texture_bytes = 0;                 ///< decoded texels, all MIP levels
    size_t triangles = 0;                     ///< instanced triangles
    size_t spheres = 0;                       ///< analytic spheres
    size_t sphere_bytes = 0;                  ///< their records (Scene::spheres, names included)
    /// The environment's prefiltered levels (bit k: kPrefilterRoughness[k]) that the used
    /// materials' glossy term kg G can read; a render builds only these (EnvironmentMap).
    uint32_t prefilter_levels = 0;
    /// The lights that may reach object `o`, in ascending order (the order of Scene::lights).
    std::span<const uint32_t> lights_of(uint32_t o) const {
        return {light_indices.data() + light_offsets[o], light_indices.data() + light_offsets[o + 1]};
    }
};

/// Object index of a hit's geometry: the instance for meshes, then spheres, quadrics and planes.
inline uint32_t object_index(const Scene& scene, uint32_t geom, uint32_t inst) {
    const uint32_t meshes = uint32_t(scene.meshes.size());
    if (geom < meshes) return inst;
    return uint32_t(scene.instances.size()) + (geom - meshes);  // spheres, quadrics, planes: geometry-id order
}

/// Analyses `scene` as rendered with the glTF mapping `mapping` (the mirror cutoff decides which
/// rough materials still reflect). O(vertices + objects x lights).
SceneAnalysis analyze_scene(const Scene& scene, const MappingOptions& mapping = {});

}  // namespace whitted
