// Numerical stability probes (docs/numerical-stability.md): the measurements behind
// `ctest -L stress` (bounded) and `whitted bench stability` (the full sweep). Each probe builds
// its scene in code, traces rays through the real accelerators and the integrator's own hit-point
// code (SceneView) and returns counts and error figures; the tests assert on them, the benchmark
// writes them to a CSV.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "accel/accelerator.h"
#include "integrator/render.h"
#include "scene/scene.h"

namespace whitted::stress {

// ---------------------------------------------------------------------------------------------
// Small helpers

/// Spacing of floats at |x| (ulp(0) = the smallest denormal).
float ulp(float x);
/// world_from_object = translate(t * kTranslationDir) * rotate(fixed, non-axis-aligned) * scale(s),
/// composed in double. kTranslationDir has non-representable components (0.8, 0.36, -0.48).
Mat4d placement(double scale, double translation, bool rotate = true);
/// Distribution figures of a sample (sorted in place): median, 99.9th percentile, max.
struct Distribution {
    size_t count = 0;
    double median = 0, p999 = 0, max = 0;
};
Distribution distribution(std::vector<double>& v);

/// UV sphere of unit radius around the origin, shared vertices (closed: poles are single
/// vertices). Normals: empty (flat shading, p_shadow = p) or the smooth sphere normals.
Mesh make_closed_sphere(int rings, int segments, bool smooth_normals);
/// Cube [-1, 1]^3, each face an n x n grid, shared vertices along every edge (closed).
Mesh make_closed_cube(int n);
/// True when every edge (after welding bit-identical positions) is used by exactly two
/// triangles with opposite orientations: a closed, consistently wound 2-manifold.
bool is_closed_mesh(const Mesh& mesh);

// ---------------------------------------------------------------------------------------------
// 1. Self-intersection at any scale

/// How secondary-ray origins are moved off a surface (p, SurfacePoint::offset_scale, unit normal):
/// by default the backend's RayOffsetPolicy, as the renderer does.
using OffsetFn = std::function<Vec3f(const Vec3f& p, float scale, const Vec3f& n)>;

/// The earlier offset (Wächter & Binder 2019 as published: 256 ulps of each coordinate,
/// 1/65536 absolute below 1/32), kept to show the suite catches what it got wrong. It knows only
/// the point: `scale` is ignored.
Vec3f wachter_binder_2019(const Vec3f& p, float scale, const Vec3f& n);

/// The surface A of the self-intersection probe.
enum class ProbeSurface : uint8_t {
    MeshSphere,       ///< tessellated unit sphere (24 x 48), closed, placed by scale/translation
    AnalyticSphere,   ///< Scene::spheres
    TiltedQuad,       ///< a large tilted square through the world origin (translation ignored):
                      ///< points near the origin on a triangle with much larger vertices
};

struct SelfIntersectionConfig {
    std::string accel = "bvh";        ///< backend name (create_accelerator)
    bool robust = false;              ///< Embree ROBUST
    ProbeSurface surface = ProbeSurface::MeshSphere;
    bool exact_point = false;         ///< emulate the proposed SceneView (hit point and Ng in double)
    bool smooth_normals = false;      ///< mesh with vertex normals (shadow origins lifted, Hanika 2021)
    double scale = 1.0;               ///< world size of the unit object
    double translation = 0.0;         ///< distance of its centre from the world origin
    size_t points = 2000;             ///< surface points (each hit by a camera ray)
    int directions = 8;               ///< secondary directions per point and ray kind
    double gap_ulps = 4.0;            ///< neighbour surfaces this many offset units away (at least):
                                      ///< ulp of the largest coordinate of A (ray_offset.h)
    double neighbour_min_cos = 1e-3;  ///< neighbours are judged for rays at least this far from grazing
    uint64_t seed = 1;
    OffsetFn offset;                  ///< empty = the backend's ray_offset() policy
    /// Experiment (`bench stability --skip-origin`): a query that hits the origin's own primitive
    /// (the same triangle; the sphere's root at the origin) is repeated from just beyond that hit,
    /// as a primitive-skipping accelerator would answer it (Cycles' "self" primitive). Shadow rays
    /// are then closest-hit queries judged like reflection rays.
    bool skip_origin = false;
    /// Experiment: >= 0 replaces `offset` by an origin formed in double from the double-precision
    /// hit point, moved this many offset units along the normal, then rounded to float away from
    /// the surface per coordinate (origin distance in [d, d + sum |n_k|] units).
    double double_origin_ulps = -1.0;
};

/// Per ray kind: 0 reflection, 1 refraction, 2 shadow.
struct SelfIntersectionResult {
    uint64_t points = 0;              ///< surface points found by a camera ray
    uint64_t camera_misses = 0;       ///< camera rays that did not find the surface (float collapse)
    uint64_t rays[3] = {0, 0, 0};
    uint64_t self_hits[3] = {0, 0, 0};        ///< the ray's first hit is its own surface
    uint64_t neighbour_misses[3] = {0, 0, 0}; ///< the neighbour surface in front was skipped
    uint64_t normal_disagreements = 0; ///< directions on the correct side of the exact normal but not
                                       ///< of the float Ng the integrator uses (skipped, counted)
    uint64_t shadow_double_counts = 0; ///< shadow rays that counted B's crossing twice (T = 0.25)
    uint64_t neighbour_unreachable = 0; ///< analytic: inward rays that skim the shell and never reach C,
                                        ///< or meet it near-tangent (ill-conditioned roots): not judged
    uint64_t neighbour_unchecked = 0; ///< rays below neighbour_min_cos: only self-hits judged
    uint64_t far_side_ties = 0;       ///< inward rays that reached A's far side just behind C
    uint64_t edge_exits = 0;          ///< inward rays leaving through an adjacent facet (exact geometry agrees)
    double max_offset_ulps = 0;       ///< largest distance of an origin from its surface, in offset
                                      ///< units ulp(max(max|p|, SurfacePoint::offset_scale))
    double min_offset_ulps = 0;       ///< smallest (signed, on the correct side > 0)
    std::vector<double> point_error_ulps;  ///< |SceneView p - exact surface|, ulp(max|p|), per point
    std::vector<double> normal_error_rad;  ///< angle between SceneView's Ng and the exact normal
    double gap_world = 0;             ///< the neighbours' distance (world units)
    bool inner_neighbour = true;      ///< false when the gap exceeds the object (collapsed): no C
};

/// Surface A (tessellated unit sphere or analytic sphere) with neighbour surfaces B (outside,
/// scale 1 + d) and C (inside, scale 1 - d) at a gap of at least gap_ulps offset units; random
/// points of A found by camera rays; from each, reflection (outward), refraction (inward) and
/// shadow (outward, from SurfacePoint::p_shadow) rays leave exactly as the integrator spawns them.
/// A hit on A is a self-intersection; an outward ray must hit B from inside, an inward one C from
/// outside (else the offset tunnelled through the neighbour).
SelfIntersectionResult probe_self_intersection(const SelfIntersectionConfig& config);

// ---------------------------------------------------------------------------------------------
// 3. Watertightness

enum class AimKind : uint8_t { Vertex = 0, EdgeMidpoint = 1, Random = 2 };

struct WatertightConfig {
    std::string accel = "bvh";
    bool robust = false;
    uint64_t rays = 100000;           ///< split evenly over vertex, edge-midpoint and random aims
    double scale = 1.0, translation = 0.0;
    uint64_t seed = 1;
    int threads = 0;                  ///< 0 = all cores
};

struct WatertightResult {
    uint64_t rays[3] = {0, 0, 0};     ///< by AimKind
    uint64_t leaks[3] = {0, 0, 0};    ///< rays from inside that hit nothing
    double seconds = 0;
};

/// Rays from points inside the closed mesh `mesh` (placed by scale/translation) aimed at its
/// vertices, edge midpoints and random points; a ray that finds no hit leaked. `inside` is a
/// point strictly inside the object (object space); origins are jittered around it.
/// A point strictly inside the closed mesh (parity of crossings in double along 3 rays, tried
/// from the box centre outwards) and its distance to the surface; false when none is found.
bool find_inside_point(const Mesh& mesh, Vec3f& inside, float& radius);

WatertightResult probe_watertight(const Mesh& mesh, const Vec3f& inside, float inside_radius,
                                  const WatertightConfig& config);

// ---------------------------------------------------------------------------------------------
// 7. Hit-point error against the double reference

struct HitErrorResult {
    uint64_t rays = 0, both_hit = 0, different_prim = 0, miss_mismatch = 0;
    std::vector<double> rel_error;    ///< |p_float - p_double| / max|p_double| per common hit
    std::vector<double> ulp_error;    ///< the same in ulp(max|p_double|)
};

/// Random rays from outside at the tessellated sphere (or analytic spheres) placed by
/// scale/translation; the float backend's hit through SceneView (the integrator's p) against
/// the exact point of the `bvh:precision=double` hit (o + t d in double).
HitErrorResult probe_hit_error(const std::string& accel, bool sphere, double scale, double translation, size_t rays,
                               uint64_t seed);

// ---------------------------------------------------------------------------------------------
// 8. Analytic quadrics: hit points, self-intersection and rims

struct QuadricProbeConfig {
    std::string accel = "bvh";
    QuadricKind kind = QuadricKind::Cylinder;  ///< capped cylinder, capped truncated cone, or disc
    double scale = 1.0, translation = 0.0;    ///< placement(scale, translation): size and distance from the origin
    size_t points = 2000;                     ///< surface points (a quarter exactly on a rim)
    int directions = 8;                       ///< secondary rays per point and kind (half grazing)
    uint64_t seed = 1;
};

struct QuadricProbeResult {
    uint64_t points = 0;
    uint64_t camera_misses = 0;       ///< camera rays at a point of A that the backend missed
                                      ///< (the double kernel's own crossings say they hit)
    uint64_t rays[3] = {0, 0, 0};     ///< 0 outward (reflection), 1 inward (refraction), 2 shadow
    uint64_t self_hits[3] = {0, 0, 0};///< outward/shadow rays that met A again; inward rays that met
                                      ///< A before half of the exact chord
    uint64_t leaks = 0;               ///< inward rays that left the closed solid without meeting it,
                                      ///< and rays from inside aimed at the rims that met nothing
    uint64_t rim_rays = 0;
    uint64_t inward_unjudged = 0;     ///< inward rays from within 16 offsets of a rim, or whose exact
                                      ///< chord is shorter than that: the offset origin cannot resolve
                                      ///< the solid there (it may round out through the other face)
    std::vector<double> point_error_ulps;  ///< |SceneView p - exact hit| in ulp(max(max|exact|, t |d|)):
                                           ///< along the surface, the float t's rounding
    std::vector<double> surface_error_ulps;///< SceneView p's distance off the surface, ulp(max|p|)
    std::vector<double> normal_error_rad;  ///< SceneView's normal against the exact one
};

/// A capped cylinder, capped truncated cone or a disc A (Scene::quadrics) placed by
/// placement(scale, translation); camera rays at random points of its side, caps and rims from
/// all angles down to grazing; SceneView's point and normal against the exact crossing (the
/// double kernel from the exact ray); secondary rays spawned as the integrator does (offset by the
/// backend's policy): outward and shadow rays must not meet A, inward rays must cross the solid to
/// its far side (judged beyond 16 offsets from a rim); rays from inside aimed exactly at the rims
/// must meet it.
QuadricProbeResult probe_quadric(const QuadricProbeConfig& config);

// ---------------------------------------------------------------------------------------------
// 2. Scale and translation invariance of images

/// Uniformly scales the whole scene by s about the world origin and then translates it by
/// t * kTranslationDir: instances, spheres, quadrics, planes, lights and cameras (transforms composed in
/// double). Point and spot intensities are multiplied by s^2, light ranges, Classic attenuation
/// coefficients (c2 / s, c3 / s^2), absorption (1 / s) and world-space checker sizes adjusted,
/// so the lighting and the image are those of the original scene. The translation is snapped to
/// a multiple of the period of world-space checkers (anchored at the world origin).
void transform_scene(Scene& scene, double s, double t);

/// Linear-RGB PSNR of a against b with peak max(1, max of b); 999 for identical images.
double psnr(const Film& a, const Film& b);
/// Largest per-channel absolute difference, and the number of pixels differing by more than tol.
double max_abs_diff(const Film& a, const Film& b, double tol, size_t* bad_pixels);
/// NaN or infinite values in the beauty buffer.
size_t nonfinite_values(const Film& film);

// ---------------------------------------------------------------------------------------------
// 4. Energy bound

struct EnergyResult {
    size_t pixels = 0;
    size_t over_bound = 0;            ///< pixels above the local-model bound (beyond the tolerance)
    double worst_ratio = 0;           ///< max over pixels of value / bound (any channel)
    size_t nonfinite = 0;
};

/// Renders `scene` (center sampling, one thread) and checks every pixel against the bound the
/// local model allows: Ia Ka + emission + sum_i Is_i fat_i (kd + ks) at each hit, summed over
/// the same ray tree with the integrator's kr / kt weights (Fresnel included).
EnergyResult check_energy_bound(const Scene& scene, const RenderSettings& settings);

}  // namespace whitted::stress
