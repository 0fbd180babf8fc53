// The reference renderer: Whitted's (1980) formula as docs/integrator.md writes it, deliberately
// plain and separate from the production path (docs/integrator.md, "The reference renderer").
//
//   I = emission + Ia Ka + sum_i Is_i fat_i s_i (kd (N.L_i) + Ks (N.H_i)^n) + Kt T + Kr R
//
// Scalar double precision, one camera ray per pixel centre, brute force over every primitive
// (each instance's world bounds first), no specialised kernels, no cutoffs, no texture filtering.
// What it does not model it refuses with a whitted::Error (check_reference_supported).
//
// How to use:
//   RenderSettings rs;  rs.aa.texture_filter = TextureFilter::None;   // as the production run
//   ReferenceImage ref = render_reference(scene, rs);                 // throws on what it refuses
//   ref.radiance[y * ref.width + x]                                   // linear RGB, after exposure
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/vecmath.h"
#include "integrator/render_settings.h"
#include "scene/scene.h"

namespace whitted {

/// One closest-hit query of a ray tree: which primitive it found (ids as Hit: geom, inst, prim;
/// all kInvalidId for a miss) and how close that hit lay to something that could have tied.
struct ReferenceHitRecord {
    uint32_t geom = UINT32_MAX;      ///< geometry id (Scene::geom_kind), UINT32_MAX = the ray missed
    uint32_t inst = UINT32_MAX;      ///< instance (meshes), UINT32_MAX for spheres and planes
    uint32_t prim = UINT32_MAX;      ///< triangle index within its mesh, 0 for spheres and planes
    double t = 0.0;                  ///< distance along the unit-direction ray
    double edge = 1.0;               ///< triangles: smallest barycentric (0 = on an edge); 1 otherwise
    double cos = 1.0;                ///< |cos| between the ray and the geometric normal (0 = grazing)
    int depth = 0;                   ///< tree depth of the ray (camera ray = 0)
    // What makes this hit's shading sensitive to small errors (for diagnosis):
    double highlight_n = 0.0;        ///< largest exponent n of a highlight that contributed here (0: none);
                                     ///< (N.H)^n multiplies a relative error of N.H by n
    bool textured = false;           ///< an image texture was read (its value follows the UV's rounding)
    bool spot_ramp = false;          ///< a spot light lit it from between its inner and outer cone
    double b1 = 0.0, b2 = 0.0;       ///< triangles: the barycentrics of vertices 1 and 2 (as Hit::u, v)
    double normal_spread = 0.0;      ///< triangles with vertex normals: max |n_i - n_j| of the world-space
                                     ///< vertex normals (how far a barycentric error moves the shading normal)
    double altitude = 0.0;           ///< triangles: the smallest altitude (world space); a hit moved by e along
                                     ///< the surface changes the barycentrics by up to e / altitude
    double min_n_dot_l = 1.0;        ///< smallest N.L of a light that lit it (a small one scales an error of N up)
    bool operator==(const ReferenceHitRecord& o) const { return geom == o.geom && inst == o.inst && prim == o.prim; }
};

/// One shadow ray of a ray tree.
struct ReferenceShadowRecord {
    Vec3d s{1.0};                    ///< the shadow factor s_i it found
    double highlight_gap = 0.0;      ///< n (1 - N.H) where kd = 0 (the light's term is the highlight
                                     ///< alone), else 0: for diagnosis, production casts no shadow ray
                                     ///< where this is >= 17 (the term is below 2^-24 Ks there)
};

/// A rendered reference image with, per pixel, its ray tree's closest hits in the order the
/// production integrator traces them (camera ray; then depth first: transmitted, reflected,
/// blended-behind rays) and its shadow rays' results.
struct ReferenceImage {
    int width = 0, height = 0;
    std::vector<Vec3d> radiance;                            ///< row-major, linear RGB times the exposure
    std::vector<std::vector<ReferenceHitRecord>> trees;     ///< per pixel
    std::vector<std::vector<ReferenceShadowRecord>> shadows;  ///< per pixel: its shadow rays, in order
};

/// Throws whitted::Error naming the first thing the reference does not model: an environment
/// (map, IBL, extracted lights), anti-aliasing other than centre, --min-weight other than 0,
/// --texture-filter mip, a crop, a camera index out of range, more than kReferenceMaxTriangles
/// instanced triangles.
void check_reference_supported(const Scene& scene, const RenderSettings& settings);

/// Instanced triangles above which the reference refuses a scene (brute force is O(triangles)
/// per ray).
constexpr size_t kReferenceMaxTriangles = 2'000'000;

/// Renders the image `settings` describe (size, camera, depth, ambient, background, exposure,
/// Fresnel, glTF mapping) with one ray per pixel centre. Checks check_reference_supported first.
/// Rows are spread over `threads` threads (0 = all); the image does not depend on it.
ReferenceImage render_reference(const Scene& scene, const RenderSettings& settings, int threads = 0);

}  // namespace whitted
