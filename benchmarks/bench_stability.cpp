// `whitted bench stability`: the full numerical-stability sweep (the bounded version
// runs in CI as `ctest -L stress`). Same probes as the tests (benchmarks/stability_probes.h):
// self-intersection at any scale (the current offset against the previous one), image invariance
// under scale and translation, watertightness (10M rays per backend and mesh), energy bound,
// refraction through slabs near grazing, deep ray trees and hit-point error. Writes
// <out>/stability.csv (one measurement per row) and prints the tables of
// docs/numerical-stability.md.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "benchmarks/bench_commands.h"
#include "benchmarks/stability_probes.h"
#include "importers/scene_loader.h"
#include "core/error.h"
#include "core/ray_offset.h"
#include "integrator/render.h"
#include "scene/scene_builder.h"
#include "shading/optics.h"

namespace whitted::app {

namespace {

namespace fs = std::filesystem;
using namespace whitted::stress;

struct BenchStabilityOptions {
    std::string out = "bench-stability";   ///< output directory (stability.csv)
    bool quick = false;                     ///< about 20x fewer rays (a smoke run)
    uint64_t watertight_rays = 10'000'000;  ///< per backend and mesh (split over 3 aim kinds)
    size_t points = 4000;                   ///< self-intersection surface points per case
    int threads = 0;                        ///< 0 = all cores
    std::string sections = "all";           ///< comma list: self,images,watertight,energy,refraction,deep,hiterror,quadrics
    std::vector<float> offset_ulps;         ///< self: sweep these offsets instead of the standard variants
    bool skip_origin = false;               ///< self: queries skip the origin's own primitive (experiment)
    bool double_origin = false;             ///< self: --offset-ulps from the double hit point, directed rounding
    float scale_factor = 1.f;               ///< self: --offset-ulps in ulps of max(max|p|, factor * offset_scale)
    std::vector<std::string> accels;        ///< self: only these backends (empty = all)
};

/// One CSV row per measurement: section, case columns, metric, value.
class Csv {
public:
    explicit Csv(const fs::path& path) : m_out(path) {
        m_out << "section,backend,subject,scale,translation,metric,value\n";
    }
    void row(const std::string& section, const std::string& backend, const std::string& subject, double scale,
             double translation, const std::string& metric, double value) {
        m_out << fmt::format("{},{},\"{}\",{:g},{:g},{},{:.9g}\n", section, backend, subject, scale, translation, metric,
                             value);
        m_out.flush();
    }

private:
    std::ofstream m_out;
};

bool wanted(const BenchStabilityOptions& o, const char* section) {
    return o.sections == "all" || ("," + o.sections + ",").find(std::string(",") + section + ",") != std::string::npos;
}

const double kScales[] = {1e-4, 1e-2, 1.0, 1e2, 1e4, 1e6};
const double kTranslations[] = {0.0, 1e3, 1e5};

std::string surface_name(ProbeSurface s, bool smooth) {
    switch (s) {
        case ProbeSurface::AnalyticSphere: return "analytic sphere";
        case ProbeSurface::TiltedQuad: return "tilted quad through origin";
        case ProbeSurface::MeshSphere: break;
    }
    return smooth ? "mesh sphere, smooth normals" : "mesh sphere";
}

// ---- 1. self-intersection -------------------------------------------------------------------
/// The backends section 1 runs (the spheres on the bvh and Embree ones, the square on all).
const std::vector<std::string> kSelfBackends = {"bvh",  "bvh:precision=double", "embree", "kdop",
                                                "grid", "octree", "brute", "brute:precision=double"};

void run_self_intersection(const BenchStabilityOptions& o, Csv& csv) {
    std::printf("\n## 1. Self-intersection (%zu points per case, 8 directions per kind)\n\n", o.points);
    std::printf("| backend | surface | offset | rays | self-hits | missed @4 ulp | missed @%g ulp |"
                " origin distance, offset ulp [min, max] | point error max, ulp | Ng error max, rad |\n"
                "|---|---|---|---:|---:|---:|---:|---|---:|---:|\n",
                double(kGuaranteedGapUlps));
    struct Variant {
        ProbeSurface surface;
        bool smooth, previous, exact;
        float offset_ulps = 0.f;  ///< with --offset-ulps: offset_ray_origin at this distance instead of the backend's policy
        bool point_unit = false;  ///< offsets in ulps of max|p| alone (ignoring offset_scale): the unit before
                                  ///< the hit primitive's coordinates were taken into account
    };
    std::vector<Variant> variants = {
        {ProbeSurface::MeshSphere, false, false, false}, {ProbeSurface::MeshSphere, false, true, false},
        {ProbeSurface::MeshSphere, true, false, false},
        {ProbeSurface::AnalyticSphere, false, false, false}, {ProbeSurface::AnalyticSphere, false, true, false},
        {ProbeSurface::TiltedQuad, false, false, false}, {ProbeSurface::TiltedQuad, false, true, false},
        {ProbeSurface::TiltedQuad, false, false, false, 0.f, true},
    };
    // --offset-ulps: the renderer's hit points with other offset distances (is a smaller one safe?).
    const bool sweep = !o.offset_ulps.empty();
    if (sweep) {
        variants.clear();
        for (const float u : o.offset_ulps)
            for (const ProbeSurface s : {ProbeSurface::MeshSphere, ProbeSurface::AnalyticSphere, ProbeSurface::TiltedQuad})
                variants.push_back({s, false, false, false, u});
    }
    auto offset_name = [&o, sweep](const Variant& v) {
        const std::string experiment = std::string(o.double_origin ? ", double origin" : "") + (o.skip_origin ? ", origin primitive skipped" : "");
        return (v.previous     ? std::string("previous (W&B 2019)")
                : v.point_unit ? std::string("ulps of max\\|p\\| alone")
                : sweep ? fmt::format("{:g} ulp", v.offset_ulps)
                                         : std::string("current")) + experiment;
    };
    // The backends without a per-primitive box test (brute, grid, octree) are the ones that found
    // large triangles again near the origin; they run the (two-triangle) tilted quad only.
    for (const std::string& accel : kSelfBackends)
        for (const Variant& v : variants) {
            if (!o.accels.empty() && std::find(o.accels.begin(), o.accels.end(), accel) == o.accels.end()) continue;
            const bool fast = accel.starts_with("bvh") || accel == "embree";
            if (!fast && v.surface != ProbeSurface::TiltedQuad) continue;
            uint64_t rays = 0, self = 0, miss4 = 0, miss12 = 0;
            double off_min = 1e300, off_max = 0, perr = 0, nerr = 0;
            for (double t : kTranslations)
                for (double s : kScales) {
                    if (v.surface == ProbeSurface::TiltedQuad && t != 0.0) continue;
                    // Only objects spanning >= 16 float steps at their position (else not a surface).
                    const bool resolvable = s >= 16.0 * double(ulp(float(t + s)));
                    for (double gap : {4.0, double(kGuaranteedGapUlps)}) {
                        SelfIntersectionConfig c;
                        c.accel = accel;
                        c.surface = v.surface;
                        c.smooth_normals = v.smooth;
                        c.exact_point = v.exact;
                        c.scale = s;
                        c.translation = t;
                        c.points = o.points;
                        c.gap_ulps = gap;
                        if (v.previous) c.offset = wachter_binder_2019;
                        if (sweep)
                            c.offset = [u = v.offset_ulps, f = o.scale_factor](const Vec3f& p, float scale, const Vec3f& n) {
                                return offset_ray_origin(p, f * scale, n, u);
                            };
                        c.skip_origin = o.skip_origin;
                        if (o.double_origin && sweep) c.double_origin_ulps = v.offset_ulps;
                        if (v.point_unit)
                            c.offset = [](const Vec3f& p, float, const Vec3f& n) { return offset_ray_origin(p, 0.f, n); };
                        SelfIntersectionResult r = probe_self_intersection(c);
                        const std::string subject = surface_name(v.surface, v.smooth) + (v.previous ? " / previous offset" : "") +
                                                    (v.point_unit ? " / point-only unit" : "") +
                                                    (sweep ? fmt::format(" / offset {:g} ulp", v.offset_ulps) : "") +
                                                    (v.exact ? " / double hit point" : "") + fmt::format(" / gap {:g} ulp", gap);
                        const uint64_t n = r.rays[0] + r.rays[1] + r.rays[2];
                        const uint64_t sh = r.self_hits[0] + r.self_hits[1] + r.self_hits[2];
                        const uint64_t nm = r.neighbour_misses[0] + r.neighbour_misses[1] + (v.smooth ? 0 : r.neighbour_misses[2]);
                        const Distribution pe = distribution(r.point_error_ulps), ne = distribution(r.normal_error_rad);
                        for (auto [metric, value] : std::initializer_list<std::pair<const char*, double>>{
                                 {"rays", double(n)}, {"self_hits", double(sh)}, {"neighbour_misses", double(nm)},
                                 {"shadow_double_counts", double(r.shadow_double_counts)},
                                 {"normal_disagreements", double(r.normal_disagreements)},
                                 {"camera_misses", double(r.camera_misses)}, {"resolvable", resolvable ? 1.0 : 0.0},
                                 {"offset_min_ulps", r.min_offset_ulps}, {"offset_max_ulps", r.max_offset_ulps},
                                 {"point_error_max_ulps", pe.max}, {"normal_error_max_rad", ne.max}})
                            csv.row("self_intersection", accel, subject, s, t, metric, value);
                        if (gap == 4.0) {
                            rays += n;
                            self += sh;
                            if (resolvable) miss4 += nm;
                        } else if (resolvable) {
                            miss12 += nm;
                            off_min = std::min(off_min, r.min_offset_ulps);
                            off_max = std::max(off_max, r.max_offset_ulps);
                            perr = std::max(perr, pe.max);
                            nerr = std::max(nerr, ne.max);
                        }
                    }
                }
            std::printf("| %s | %s | %s%s | %llu | %llu | %llu | %llu | [%.1f, %.1f] | %.1f | %.2g |\n", accel.c_str(),
                        surface_name(v.surface, v.smooth).c_str(), offset_name(v).c_str(),
                        v.exact ? " (double hit point, probe emulation)" : "", (unsigned long long)rays,
                        (unsigned long long)self, (unsigned long long)miss4, (unsigned long long)miss12,
                        off_min == 1e300 ? 0.0 : off_min, off_max, perr, nerr);
            std::fflush(stdout);
        }
}

// ---- 2. images ------------------------------------------------------------------------------
void run_images(const BenchStabilityOptions& o, Csv& csv) {
    std::printf("\n## 2. Scale and translation invariance (64 px wide, pixel centres; reference: unscaled, "
                "bvh:precision=double)\n\n| scene | scale | translation | embree PSNR | bvh PSNR | bvh double PSNR |"
                " worst bad pixels (> 0.02) |\n|---|---:|---:|---:|---:|---:|---:|\n");
    const char* scenes[] = {"default.glb", "whitted1980.json", "transparent_shadows.json", "glass_mirror_room.json"};
    for (const char* name : scenes) {
        const Scene base = load_scene(std::string(WHITTED_SOURCE_DIR) + "/assets/scenes/" + name);
        auto render = [&](const Scene& s, const char* accel) {
            RenderSettings rs;
            apply_scene_settings(s.settings, rs);
            rs.width = 64;
            rs.height = 0;
            rs.aa = AaSettings{};
            rs.accel = accel;
            rs.threads = o.threads;
            return Renderer(s, rs).render();
        };
        const Film reference = render(base, "bvh:precision=double");
        for (double s : {1e-3, 1e-1, 1.0, 1e1, 1e3, 1e5})
            for (double t : {0.0, 1e3, 1e5}) {
                Scene scene = base;
                transform_scene(scene, s, t);
                double p[3];
                size_t worst_bad = 0;
                int k = 0;
                for (const char* accel : {"embree", "bvh", "bvh:precision=double"}) {
                    const Film img = render(scene, accel);
                    size_t bad = 0;
                    max_abs_diff(img, reference, 0.02, &bad);
                    p[k++] = psnr(img, reference);
                    worst_bad = std::max(worst_bad, bad);
                    csv.row("images", accel, name, s, t, "psnr", p[k - 1]);
                    csv.row("images", accel, name, s, t, "bad_pixels", double(bad));
                    csv.row("images", accel, name, s, t, "nonfinite", double(nonfinite_values(img)));
                }
                std::printf("| %s | %g | %g | %.1f | %.1f | %.1f | %zu / %zu |\n", name, s, t, p[0], p[1], p[2], worst_bad,
                            reference.beauty.size());
            }
        std::fflush(stdout);
    }
}

// ---- 3. watertightness ----------------------------------------------------------------------
void run_watertight(const BenchStabilityOptions& o, Csv& csv) {
    std::printf("\n## 3. Watertightness (%llu rays per backend and mesh, from inside; vertex / edge midpoint / random aims)\n\n"
                "| mesh | placement | backend | leaks vertex | leaks edge | leaks random | leak rate | Mrays/s |\n"
                "|---|---|---|---:|---:|---:|---:|---:|\n",
                (unsigned long long)o.watertight_rays);
    struct Named {
        std::string name;
        Mesh mesh;
    };
    std::vector<Named> meshes;
    meshes.push_back({"sphere 48x96", make_closed_sphere(48, 96, false)});
    meshes.push_back({"cube 8x8", make_closed_cube(8)});
    meshes.push_back({"Duck.glb", load_scene(std::string(WHITTED_SOURCE_DIR) + "/assets/gltf/Duck/glTF-Binary/Duck.glb").meshes.at(0)});
    for (const Named& m : meshes) {
        Vec3f inside;
        float radius = 0.f;
        if (!find_inside_point(m.mesh, inside, radius)) throw Error("bench stability: no inside point for " + m.name);
        for (const auto& [s, t] : {std::pair{1.0, 0.0}, std::pair{1e3, 1e5}})
            for (const char* accel : {"bvh", "bvh:precision=double", "kdop", "grid", "octree", "brute", "embree", "embree robust"}) {
                WatertightConfig c;
                c.accel = std::string(accel) == "embree robust" ? "embree" : accel;
                c.robust = std::string(accel) == "embree robust";
                c.rays = std::string(accel) == "brute" ? std::min<uint64_t>(o.watertight_rays, 200000) : o.watertight_rays;
                c.scale = s;
                c.translation = t;
                c.threads = o.threads;
                const WatertightResult r = probe_watertight(m.mesh, inside, radius, c);
                const uint64_t rays = r.rays[0] + r.rays[1] + r.rays[2], leaks = r.leaks[0] + r.leaks[1] + r.leaks[2];
                for (int k = 0; k < 3; ++k) {
                    const char* aim = k == 0 ? "vertex" : k == 1 ? "edge" : "random";
                    csv.row("watertight", accel, m.name, s, t, std::string("rays_") + aim, double(r.rays[k]));
                    csv.row("watertight", accel, m.name, s, t, std::string("leaks_") + aim, double(r.leaks[k]));
                }
                std::printf("| %s | s=%g t=%g | %s | %llu | %llu | %llu | %.2g | %.2f |\n", m.name.c_str(), s, t, accel,
                            (unsigned long long)r.leaks[0], (unsigned long long)r.leaks[1], (unsigned long long)r.leaks[2],
                            double(leaks) / double(rays), double(rays) / r.seconds * 1e-6);
                std::fflush(stdout);
            }
    }
}

// ---- 4. energy bound and refraction -----------------------------------------------------------
void run_energy(const BenchStabilityOptions& o, Csv& csv) {
    std::printf("\n## 4a. Energy bound on the bundled scenes (128 px wide, pixel centres)\n\n"
                "| scene | backend | Fresnel | pixels | over the bound | worst value / bound | non-finite |\n"
                "|---|---|---|---:|---:|---:|---:|\n");
    for (const char* name : {"default.glb", "whitted1980.json", "transparent_shadows.json", "glass_mirror_room.json"}) {
        const Scene scene = load_scene(std::string(WHITTED_SOURCE_DIR) + "/assets/scenes/" + name);
        for (const char* accel : {"embree", "bvh"})
            for (bool fresnel : {false, true}) {
                RenderSettings rs;
                apply_scene_settings(scene.settings, rs);
                rs.width = 128;
                rs.height = 0;
                rs.accel = accel;
                rs.threads = o.threads;
                rs.integrator.fresnel = fresnel;
                const EnergyResult r = check_energy_bound(scene, rs);
                csv.row("energy", accel, std::string(name) + (fresnel ? " fresnel" : ""), 1, 0, "over_bound", double(r.over_bound));
                csv.row("energy", accel, std::string(name) + (fresnel ? " fresnel" : ""), 1, 0, "worst_ratio", r.worst_ratio);
                std::printf("| %s | %s | %s | %zu | %zu | %.6f | %zu |\n", name, accel, fresnel ? "on" : "off", r.pixels,
                            r.over_bound, r.worst_ratio, r.nonfinite);
            }
    }
}

void run_refraction(Csv& csv) {
    std::printf("\n## 4b. Parallel slab: exit direction error |out - in| (src/shading/optics.h refract, float)\n\n"
                "| incidence (deg) | ior 1.0 | ior 1.0001 | ior 1.5 | ior 2.4 |\n|---:|---:|---:|---:|---:|\n");
    for (double deg : {0.0, 45.0, 80.0, 89.0, 89.9, 89.95, 89.99, 89.999}) {
        std::printf("| %g |", deg);
        for (float ior : {1.0f, 1.0001f, 1.5f, 2.4f}) {
            const double th = deg * kPiD / 180.0;
            const Vec3f I = Vec3f(Vec3d(std::sin(th), 0.0, -std::cos(th)));
            const auto T = refract(I, Vec3f{0, 0, 1}, 1.f / ior);
            const auto O = T ? refract(*T, Vec3f{0, 0, 1}, ior) : std::nullopt;
            const double err = O ? length(Vec3d(*O) - Vec3d(I)) : -1.0;
            csv.row("refraction", "optics", fmt::format("ior {:g}", ior), 1, 0, fmt::format("exit_error_at_{:g}deg", deg), err);
            if (O) std::printf(" %.2g |", err);
            else std::printf(" TIR on exit |");
        }
        std::printf("\n");
    }
}

// ---- 5. deep trees --------------------------------------------------------------------------
void run_deep(Csv& csv) {
    std::printf("\n## 5. Parallel mirrors (kr 0.9, Ia Ka 0.1): radiance against a (1 - r^(D+1)) / (1 - r)\n\n"
                "| max depth | pixel | series | relative error | reflection rays per pixel | seconds |\n"
                "|---:|---:|---:|---:|---:|---:|\n");
    for (int depth : {1, 2, 5, 10, 20, 50, 100, 200}) {
        Scene s;
        WhittedCoeffs c;
        c.ka = Color(0.5f);
        c.kr = Color(0.9f);
        const uint32_t m = add_classic_material(s, c, "mirror");
        Plane a, b;
        a.normal = {0, 0, 1};
        b.point = {0, 0, 1};
        b.normal = {0, 0, -1};
        a.material = b.material = m;
        s.planes = {a, b};
        s.cameras.push_back(make_camera(CameraType::Orthographic, {0.1, 0.2, 0.5}, {0, 0, -1}, {0, 1, 0}, 0.01));
        RenderSettings rs;
        rs.width = rs.height = 4;
        rs.integrator.max_depth = depth;
        rs.integrator.ambient = Color(0.2f);
        RenderStats st;
        const Film f = Renderer(s, rs).render(&st);
        const double want = 0.1 * (1.0 - std::pow(0.9, depth + 1)) / 0.1;
        const double got = f.beauty[0].x;
        csv.row("deep_tree", "embree", "parallel mirrors", 1, 0, fmt::format("rel_error_depth_{}", depth), std::fabs(got - want) / want);
        std::printf("| %d | %.7f | %.7f | %.2g | %.0f | %.4f |\n", depth, got, want, std::fabs(got - want) / want,
                    double(st.rays.reflection) / 16.0, st.render_seconds);
    }
}

// ---- 7. hit-point error ---------------------------------------------------------------------
void run_hit_error(const BenchStabilityOptions& o, Csv& csv) {
    std::printf("\n## 7. Hit-point error: float hit through SceneView against the exact point of the double reference\n\n"
                "| backend | surface | scale | translation | hits | median ulp | p99.9 ulp | max ulp | median rel | max rel |\n"
                "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    const size_t rays = o.quick ? 5000 : 100000;
    for (const char* accel : {"bvh", "embree"})
        for (bool sphere : {false, true})
            for (double t : kTranslations)
                for (double s : kScales) {
                    if (!(s >= 16.0 * double(ulp(float(t + s))))) continue;
                    HitErrorResult r = probe_hit_error(accel, sphere, s, t, rays, 5);
                    const Distribution u = distribution(r.ulp_error), e = distribution(r.rel_error);
                    const std::string subject = sphere ? "analytic sphere" : "mesh sphere";
                    for (auto [metric, value] : std::initializer_list<std::pair<const char*, double>>{
                             {"hits", double(r.both_hit)}, {"median_ulp", u.median}, {"p999_ulp", u.p999}, {"max_ulp", u.max},
                             {"median_rel", e.median}, {"p999_rel", e.p999}, {"max_rel", e.max},
                             {"hit_miss_mismatch", double(r.miss_mismatch)}})
                        csv.row("hit_error", accel, subject, s, t, metric, value);
                    std::printf("| %s | %s | %g | %g | %llu | %.2f | %.2f | %.2f | %.2g | %.2g |\n", accel, subject.c_str(), s, t,
                                (unsigned long long)r.both_hit, u.median, u.p999, u.max, e.median, e.max);
                }
}

// ---- 8. analytic quadrics ---------------------------------------------------------------------
void run_quadrics(const BenchStabilityOptions& o, Csv& csv) {
    std::printf("\n## 8. Analytic quadrics: self-hits, leaks and hit-point error (%zu points per case, 8 directions per kind)\n\n"
                "| backend | quadric | scale | translation | points | self-hits out/in/shadow | leaks | lost hits | "
                "inward unjudged | median ulp | max ulp | max ulp off the surface | max normal error (rad) |\n"
                "|---|---|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|\n",
                o.points);
    for (const char* accel : {"bvh", "embree"})
        for (const QuadricKind kind : {QuadricKind::Cylinder, QuadricKind::Cone, QuadricKind::Disc})
            for (double t : kTranslations)
                for (double s : kScales) {
                    if (!(s >= 16.0 * double(ulp(float(t + s))))) continue;
                    QuadricProbeConfig c;
                    c.accel = accel;
                    c.kind = kind;
                    c.scale = s;
                    c.translation = t;
                    c.points = o.points;
                    QuadricProbeResult r = probe_quadric(c);
                    const Distribution u = distribution(r.point_error_ulps), n = distribution(r.normal_error_rad),
                                       off = distribution(r.surface_error_ulps);
                    const char* subject = kind == QuadricKind::Cylinder ? "capped cylinder" : kind == QuadricKind::Cone ? "capped cone" : "disc";
                    for (auto [metric, value] : std::initializer_list<std::pair<const char*, double>>{
                             {"points", double(r.points)}, {"self_hits_out", double(r.self_hits[0])},
                             {"self_hits_in", double(r.self_hits[1])}, {"self_hits_shadow", double(r.self_hits[2])},
                             {"leaks", double(r.leaks)}, {"lost_hits", double(r.camera_misses)},
                             {"inward_unjudged", double(r.inward_unjudged)}, {"max_off_surface_ulp", off.max},
                             {"median_ulp", u.median},
                             {"max_ulp", u.max}, {"max_normal_rad", n.max}})
                        csv.row("quadrics", accel, subject, s, t, metric, value);
                    std::printf("| %s | %s | %g | %g | %llu | %llu/%llu/%llu | %llu | %llu | %llu | %.2f | %.2f | %.2f | %.1e |\n", accel,
                                subject, s, t, (unsigned long long)r.points, (unsigned long long)r.self_hits[0],
                                (unsigned long long)r.self_hits[1], (unsigned long long)r.self_hits[2], (unsigned long long)r.leaks,
                                (unsigned long long)r.camera_misses, (unsigned long long)r.inward_unjudged, u.median, u.max, off.max,
                                n.max);
                }
}

int run_bench_stability(BenchStabilityOptions o) {
    if (o.quick) {
        o.watertight_rays = std::min<uint64_t>(o.watertight_rays, 300000);
        o.points = std::min<size_t>(o.points, 300);
    }
    const fs::path out(o.out);
    fs::create_directories(out);
    Csv csv(out / "stability.csv");
    const auto start = std::chrono::steady_clock::now();
    std::printf("# whitted bench stability%s\n", o.quick ? " --quick" : "");
    if (wanted(o, "self")) run_self_intersection(o, csv);
    if (wanted(o, "images")) run_images(o, csv);
    if (wanted(o, "watertight")) run_watertight(o, csv);
    if (wanted(o, "energy")) run_energy(o, csv);
    if (wanted(o, "refraction")) run_refraction(csv);
    if (wanted(o, "deep")) run_deep(csv);
    if (wanted(o, "hiterror")) run_hit_error(o, csv);
    if (wanted(o, "quadrics")) run_quadrics(o, csv);
    std::printf("\nwrote %s in %.0f s\n", (out / "stability.csv").c_str(),
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    return 0;
}

}  // namespace

Command register_bench_stability(CLI::App& bench) {
    auto o = std::make_shared<BenchStabilityOptions>();
    CLI::App* app = bench.add_subcommand("stability", "Numerical stability sweep (docs/numerical-stability.md)");
    app->add_option("--out", o->out, "Output directory (stability.csv)")->capture_default_str();
    app->add_flag("--quick", o->quick, "About 20x fewer rays (a smoke run)");
    app->add_option("--watertight-rays", o->watertight_rays, "Rays per backend and mesh in the watertightness sweep")
        ->check(CLI::Range(uint64_t(3), uint64_t(1) << 40))->capture_default_str();
    app->add_option("--points", o->points, "Surface points per self-intersection case")
        ->check(CLI::Range(size_t(1), size_t(1) << 30))->capture_default_str();
    app->add_option("--threads", o->threads, "Worker threads (0 = all cores)")->check(CLI::Range(0, 1024))->capture_default_str();
    app->add_option("--offset-ulps", o->offset_ulps,
                    "Self-intersection: sweep these ray-offset distances (ulps of max(max|p|, the hit primitive's coordinates)) with the renderer's hit points "
                    "instead of the standard variants")
        ->delimiter(',')
        ->check(CLI::Range(0.f, 4096.f));
    app->add_option("--scale-factor", o->scale_factor,
                    "Self-intersection: --offset-ulps in ulps of max(max|p|, factor x the hit primitive's coordinates)")
        ->check(CLI::Range(0.f, 1.f));
    app->add_option("--accels", o->accels, "Self-intersection: only these backends (comma list, e.g. bvh:precision=double)")
        ->delimiter(',')
        ->check(CLI::IsMember(kSelfBackends));
    app->add_flag("--skip-origin", o->skip_origin,
                  "Self-intersection experiment: queries that hit the origin's own primitive are repeated beyond it");
    app->add_flag("--double-origin", o->double_origin,
                  "Self-intersection experiment: --offset-ulps origins formed in double from the double hit point and "
                  "rounded away from the surface");
    app->add_option("--sections", o->sections, "Comma list of self,images,watertight,energy,refraction,deep,hiterror,quadrics or all")
        ->capture_default_str();
    return Command{app, [o] { return run_bench_stability(*o); }};
}

}  // namespace whitted::app
