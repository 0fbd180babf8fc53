// Embree (the production path) against the in-house `bvh` (the reference path), on bundled scenes.
//
// Per ray: the same closest primitive, or a tie as judged by the double-precision reference
// (`bvh:precision=double`): both backends' hits lie within 1e-5 relative of the reference t.
// Anything else is a divergence; its fraction must stay <= 0.1% (the target).
// Per image: render with both; pixels whose primitive/instance-ID AOVs agree must match in beauty
// within 1e-4 relative; pixels whose IDs differ are counted (target <= 0.1% of the image) and
// must lie on ID boundaries. The same figures are printed for Embree with RTC_SCENE_FLAG_ROBUST.
#include <gtest/gtest.h>

#include <cstdio>

#include "importers/scene_loader.h"
#include "renderer/integrator/render.h"
#include "tests/unit/test_accel_util.h"

namespace whitted {
namespace {

using namespace whitted::test;

const char* const kScenes[] = {"/scenes/default.glb", "/gltf/Duck/glTF-Binary/Duck.glb",
                               "/gltf/GlassHurricaneCandleHolder/glTF-Binary/GlassHurricaneCandleHolder.glb",
                               "/gltf/SimpleInstancing/glTF-Binary/SimpleInstancing.glb"};

Scene load(const char* rel) {
    ImportOptions io;
    io.load_textures = false;
    return load_scene(std::string(WHITTED_ASSETS_DIR) + rel, io);
}

struct RayFigures {
    size_t rays = 0, same = 0, ties = 0, diverge = 0;
};

constexpr uint32_t kRandomRays = 3000;

/// Figures for the random rays (the first kRandomRays of make_rays) and, separately, for the
/// edge cases (through vertices and edge midpoints, origins on surfaces, axis-parallel).
std::pair<RayFigures, RayFigures> compare_per_ray(const Scene& s, bool robust) {
    OpaqueFilter filter;
    AccelConfig cfg;
    cfg.robust = robust;
    const auto embree = create_accelerator("embree", s, filter, cfg);
    const auto bvh = create_accelerator("bvh", s, filter);
    const auto ref = create_accelerator("bvh:precision=double", s, filter);
    RayFigures random, edge;
    const std::vector<Ray> rays = make_rays(s, kRandomRays, 77);
    for (size_t i = 0; i < rays.size(); ++i) {
        const Ray& r = rays[i];
        RayFigures& f = i < kRandomRays ? random : edge;
        const Hit e = embree->intersect(r, RayKind::Camera), b = bvh->intersect(r, RayKind::Camera);
        ++f.rays;
        if (e.valid() == b.valid() && (!e.valid() || (e.prim == b.prim && e.inst == b.inst))) {
            ++f.same;
            continue;
        }
        const Hit d = ref->intersect(r, RayKind::Camera);
        auto near_ref = [&](const Hit& h) {
            return h.valid() && d.valid() && std::fabs(h.t - d.t) <= 1e-5f * d.t;
        };
        if (near_ref(e) && near_ref(b)) ++f.ties;
        else ++f.diverge;
    }
    return {random, edge};
}

TEST(AccelEmbree, PerRayAgainstBvh) {
    for (const char* rel : kScenes) {
        const Scene s = load(rel);
        for (bool robust : {false, true}) {
            const auto [f, g] = compare_per_ray(s, robust);
            std::printf("[ per-ray ] %-40.40s embree%-8s random: %zu rays, %zu same, %zu ties, %zu diverge (%.3f%%) | "
                        "edge cases: %zu rays, %zu ties, %zu diverge (%.2f%%)\n",
                        rel, robust ? "(robust)" : "", f.rays, f.same, f.ties, f.diverge,
                        100.0 * double(f.diverge) / double(f.rays), g.rays, g.ties, g.diverge,
                        100.0 * double(g.diverge) / double(g.rays));
            // Random rays must agree; the edge cases (rays aimed exactly at vertices and edges,
            // starting on surfaces) are where Embree's non-watertight test differs by design:
            // reported, not asserted.
            EXPECT_LE(double(f.diverge), 0.001 * double(f.rays)) << rel;
        }
    }
}

struct ImageFigures {
    size_t pixels = 0, id_diverge = 0, off_boundary = 0, beauty_off = 0;
};

ImageFigures compare_images(const Scene& s, bool robust) {
    RenderSettings rs;
    rs.width = 120;
    rs.height = 80;
    rs.aovs.prim_id = rs.aovs.inst_id = true;
    rs.robust = robust;
    rs.accel = "embree";
    const Film e = Renderer(s, rs).render();
    rs.accel = "bvh";
    const Film b = Renderer(s, rs).render();
    ImageFigures f;
    const int w = e.width(), h = e.height();
    auto id_at = [&](const Film& film, int x, int y) {
        const size_t i = size_t(y) * size_t(w) + size_t(x);
        return std::pair(film.prim_id[i], film.inst_id[i]);
    };
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const size_t i = size_t(y) * size_t(w) + size_t(x);
            ++f.pixels;
            if (id_at(e, x, y) != id_at(b, x, y)) {
                ++f.id_diverge;
                // On an ID boundary: some 8-neighbour has another ID in Embree's image.
                bool boundary = false;
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) {
                        const int nx = x + dx, ny = y + dy;
                        if (nx >= 0 && ny >= 0 && nx < w && ny < h && id_at(e, nx, ny) != id_at(e, x, y)) boundary = true;
                    }
                f.off_boundary += !boundary;
                continue;
            }
            for (int k = 0; k < 3; ++k) {
                const float a = e.beauty[i][k], c = b.beauty[i][k];
                if (std::fabs(a - c) > 1e-4f * std::max(std::fabs(a), std::fabs(c)) + 1e-7f) {
                    ++f.beauty_off;
                    break;
                }
            }
        }
    return f;
}

TEST(AccelEmbree, PerImageAgainstBvh) {
    for (const char* rel : kScenes) {
        const Scene s = load(rel);
        for (bool robust : {false, true}) {
            const ImageFigures f = compare_images(s, robust);
            std::printf("[ image ] %-70s embree%s vs bvh: %zu px, ID diverge %zu (%.3f%%, %zu off boundaries), "
                        "beauty off in ID-agreeing px %zu (%.3f%%)\n",
                        rel, robust ? "(robust)" : "", f.pixels, f.id_diverge, 100.0 * double(f.id_diverge) / double(f.pixels),
                        f.off_boundary, f.beauty_off, 100.0 * double(f.beauty_off) / double(f.pixels));
            EXPECT_LE(double(f.id_diverge), 0.001 * double(f.pixels)) << rel;
            EXPECT_EQ(f.off_boundary, 0u) << rel;
        }
    }
}

/// Transparent-shadow queries agree between Embree (duplicates removed by its filter) and every
/// in-house backend on a scene with glass and a tinted filter.
TEST(AccelEmbree, TransmittanceMatchesInHouse) {
    const Scene s = load("/scenes/default.glb");
    SceneView view(s, MappingOptions{});
    const auto embree = create_accelerator("embree", s, view);
    // Random segments only: segments ending exactly on a vertex or edge (t == tfar) are decided
    // by the last ulp of t, which Embree and the watertight test compute differently.
    std::vector<Ray> rays = make_rays(s, 1500, 3);
    rays.resize(1500);
    for (const char* name : {"bvh", "grid", "octree", "kdop", "brute"}) {
        const auto accel = create_accelerator(name, s, view);
        size_t bad = 0, transparent = 0;
        for (Ray r : rays) {
            r.tfar = 1.f;
            const Color a = embree->transmittance(r), b = accel->transmittance(r);
            transparent += a.x > 0.f && a.x < 1.f;
            for (int k = 0; k < 3; ++k) bad += std::fabs(a[k] - b[k]) > 1e-5f * std::max(1e-3f, a[k]);
        }
        std::printf("[ shadow ] %-8s %zu segments (%zu partly transparent): %zu channel mismatches vs embree\n", name,
                    rays.size(), transparent, bad);
        EXPECT_LE(double(bad), 0.002 * double(rays.size())) << name;
    }
}

}  // namespace
}  // namespace whitted
