// WhittedIntegrator::trace_camera (rows of camera rays, one batch query per row in the specialised
// kernels: Embree packets) against trace() one ray at a time. The radiance, the first-hit data
// and the ray counts must be identical; the only allowed difference is a pixel whose batch hit
// names another primitive at the same closest t as the single-ray hit (shared edges and vertices:
// Accelerator::intersect over a span allows that), which is counted and printed. Correctness
// only: no timings here.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "importers/scene_loader.h"
#include "integrator/camera.h"
#include "integrator/render.h"
#include "integrator/whitted_integrator.h"

namespace whitted {
namespace {

const std::string kAssets = WHITTED_ASSETS_DIR;

/// Forwards every query and counts the batch queries (to see which path trace_camera took).
class CountingAccelerator final : public Accelerator {
public:
    explicit CountingAccelerator(const Accelerator& inner) : m_inner(inner) {}
    Hit intersect(const Ray& ray, RayKind kind) const override { return m_inner.intersect(ray, kind); }
    void intersect(std::span<const Ray> rays, RayKind kind, std::span<Hit> hits) const override {
        ++batches;
        m_inner.intersect(rays, kind, hits);
    }
    Color transmittance(const Ray& ray) const override { return m_inner.transmittance(ray); }
    std::string name() const override { return m_inner.name(); }
    RayOffsetPolicy ray_offset() const override { return m_inner.ray_offset(); }
    AccelStats stats() const override { return m_inner.stats(); }
    mutable size_t batches = 0;  // single-threaded test

private:
    const Accelerator& m_inner;
};

bool same(const Color& a, const Color& b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

bool same(const PrimaryInfo& a, const PrimaryInfo& b) {
    return a.hit == b.hit && a.depth == b.depth && a.normal.x == b.normal.x && a.normal.y == b.normal.y &&
           a.normal.z == b.normal.z && same(a.albedo, b.albedo) && a.prim == b.prim && a.inst == b.inst;
}

struct Outcome {
    size_t rays = 0, hits = 0, ties = 0, batches = 0;
};

/// Traces every pixel centre of a `width`-wide image of `path` in rows of `row` samples (as the
/// tile loops would: a tile row of up to 16 pixels), with trace_camera and with trace, and
/// compares them. Mismatches that are not ties fail the test.
Outcome compare_rows(const std::string& path, const std::string& accel, bool specialize, float min_weight,
                     int width = 64, int row = 16) {
    SCOPED_TRACE(path + " on " + accel + (specialize ? ", specialised" : ", general"));
    const Scene scene = load_scene(path);
    RenderSettings rs;
    apply_scene_settings(scene.settings, rs);
    rs.width = width;
    rs.height = 0;
    rs.accel = accel;
    rs.threads = 1;
    rs.progress = false;
    const Renderer renderer(scene, rs);
    const ImageSize size = renderer.image_size();
    const CameraModel camera(scene.cameras[size_t(rs.camera)], size.width, size.height);
    const RayCone cone = camera.pixel_cone();
    IntegratorSettings is = rs.integrator;
    is.specialize = specialize;
    is.min_weight = min_weight;
    const CountingAccelerator counting(renderer.accelerator());
    const WhittedIntegrator integrator(renderer.view(), counting, is);

    Outcome out;
    RayCounters batch_counts, single_counts;
    std::vector<Ray> rays;
    std::vector<Color> radiance;
    std::vector<PrimaryInfo> primary;
    for (int y = 0; y < size.height; ++y)
        for (int x0 = 0; x0 < size.width; x0 += row) {
            rays.clear();
            for (int x = x0; x < std::min(size.width, x0 + row); ++x) rays.push_back(camera.generate(x + 0.5, y + 0.5));
            radiance.assign(rays.size(), Color(-1.f));
            primary.assign(rays.size(), PrimaryInfo{});
            integrator.trace_camera(rays, radiance, batch_counts, cone, primary);
            std::vector<Hit> batch_hits(rays.size());
            renderer.accelerator().intersect(std::span<const Ray>(rays), RayKind::Camera, std::span<Hit>(batch_hits));
            for (size_t i = 0; i < rays.size(); ++i) {
                PrimaryInfo p;
                const Color c = integrator.trace(rays[i], RayKind::Camera, 0, single_counts, &p, cone);
                ++out.rays;
                out.hits += p.hit;
                if (same(c, radiance[i]) && same(p, primary[i])) continue;
                // Allowed only where the batch named another primitive at the same t.
                const Hit single = renderer.accelerator().intersect(rays[i], RayKind::Camera);
                const Hit& b = batch_hits[i];
                const bool tie = single.valid() && b.valid() && single.t == b.t &&
                                 (single.prim != b.prim || single.geom != b.geom || single.inst != b.inst);
                EXPECT_TRUE(tie) << "pixel (" << x0 + int(i) << ", " << y << "): trace_camera (" << radiance[i].x
                                 << ", " << radiance[i].y << ", " << radiance[i].z << ") vs trace (" << c.x << ", "
                                 << c.y << ", " << c.z << "), hits t " << b.t << " / " << single.t << ", prim "
                                 << b.prim << " / " << single.prim;
                out.ties += tie;
            }
        }
    out.batches = counting.batches;
    // Ray counts: identical unless a tie changed what a pixel's ray tree did.
    if (out.ties == 0) {
        EXPECT_TRUE(batch_counts == single_counts);
    }
    EXPECT_EQ(batch_counts.camera, out.rays);
    std::printf("[ trace_camera ] %s on %s, %s: %zu rays, %zu hits, %zu tie pixels, %zu batch queries\n",
                path.substr(kAssets.size()).c_str(), accel.c_str(), specialize ? "specialised" : "general", out.rays,
                out.hits, out.ties, out.batches);
    return out;
}

const std::vector<std::string>& scenes() {
    static const std::vector<std::string> s = {
        kAssets + "/scenes/whitted1980.json",
        kAssets + "/scenes/transparent_shadows.json",
        kAssets + "/scenes/glass_mirror_room.json",
        kAssets + "/scenes/default.glb",
        kAssets + "/gltf/Duck/glTF-Binary/Duck.glb",
        kAssets + "/gltf/GlassHurricaneCandleHolder/glTF-Binary/GlassHurricaneCandleHolder.glb",
        kAssets + "/gltf/SimpleInstancing/glTF-Binary/SimpleInstancing.glb",
        kAssets + "/gltf/NegativeScaleTest/glTF-Binary/NegativeScaleTest.glb",
        kAssets + "/gltf/BoxVertexColors/glTF-Binary/BoxVertexColors.glb",
    };
    return s;
}

class TraceCamera : public ::testing::TestWithParam<const char*> {};

// The specialised kernels: one batch query per row, same radiance as trace() ray by ray.
TEST_P(TraceCamera, SpecialisedRowsMatchSingleRays) {
    size_t ties = 0, rays = 0;
    for (const std::string& path : scenes()) {
        const Outcome o = compare_rows(path, GetParam(), true, 0.f);
        EXPECT_GT(o.hits, 0u);
        EXPECT_GT(o.batches, 0u);  // the batch query is used
        ties += o.ties;
        rays += o.rays;
    }
    // Ties are rare by nature (a ray through an edge to the float): far below 1 in 1000.
    EXPECT_LE(ties * 1000, rays);
}

// The adaptive cutoff does not change the equivalence (same weights along each path).
TEST_P(TraceCamera, SpecialisedRowsMatchWithMinWeight) {
    for (const char* p : {"/scenes/glass_mirror_room.json", "/scenes/default.glb"}) {
        const Outcome o = compare_rows(kAssets + p, GetParam(), true, 1.f / 255.f);
        EXPECT_LE(o.ties * 1000, o.rays);
    }
}

// The general kernel keeps tracing one ray at a time (the baseline packets are measured
// against): no batch query, and exactly trace()'s results.
TEST_P(TraceCamera, GeneralKernelTracesRayByRay) {
    for (const char* p : {"/scenes/whitted1980.json", "/gltf/Duck/glTF-Binary/Duck.glb"}) {
        const Outcome o = compare_rows(kAssets + p, GetParam(), false, 0.f);
        EXPECT_EQ(o.batches, 0u);
        EXPECT_EQ(o.ties, 0u);
    }
}

INSTANTIATE_TEST_SUITE_P(Backends, TraceCamera, ::testing::Values("embree", "bvh"));

/// generate_row (blocks of packed doubles, plus a scalar tail) gives generate()'s rays bit for
/// bit: perspective and orthographic cameras, a rotated and translated frame, near and far planes,
/// rows of every length around the block size, sub-pixel steps and positions far off the image.
TEST(CameraRows, GenerateRowEqualsGenerate) {
    auto bits_equal = [](const Ray& a, const Ray& b) {
        return std::memcmp(&a.org, &b.org, sizeof(Vec3f)) == 0 && std::memcmp(&a.dir, &b.dir, sizeof(Vec3f)) == 0 &&
               std::memcmp(&a.tnear, &b.tnear, sizeof(float)) == 0 && std::memcmp(&a.tfar, &b.tfar, sizeof(float)) == 0;
    };
    Mat4d frame = Mat4d::identity();
    // A rotation about an oblique axis (orthonormal columns) and a translation far from the origin.
    const double c = std::cos(0.7), s = std::sin(0.7);
    frame(0, 0) = c, frame(0, 1) = -s * 0.6, frame(0, 2) = s * 0.8, frame(0, 3) = 1234.5;
    frame(1, 0) = s, frame(1, 1) = c * 0.6, frame(1, 2) = -c * 0.8, frame(1, 3) = -0.125;
    frame(2, 0) = 0, frame(2, 1) = 0.8, frame(2, 2) = 0.6, frame(2, 3) = 1e5;
    size_t rays_checked = 0, mismatches = 0;
    for (const CameraType type : {CameraType::Perspective, CameraType::Orthographic})
        for (const double zfar : {0.0, 50.0}) {
            Camera cam;
            cam.type = type;
            cam.yfov = 1.1;
            cam.ymag = 3.0;
            cam.znear = 0.01;
            cam.zfar = zfar;
            cam.world_from_camera = frame;
            const CameraModel model(cam, 333, 177);
            for (const size_t n : {size_t(1), size_t(15), size_t(16), size_t(17), size_t(33), size_t(64), size_t(70)})
                for (const double dx : {1.0, 0.125})
                    for (const double x0 : {0.0, 0.5, 320.25, -40.0})
                        for (const double y : {0.0, 88.5, 176.999, 400.0}) {
                            std::vector<Ray> row(n);
                            model.generate_row(x0, dx, y, row);
                            for (size_t i = 0; i < n; ++i) {
                                ++rays_checked;
                                if (!bits_equal(row[i], model.generate(x0 + double(i) * dx, y))) ++mismatches;
                            }
                        }
        }
    EXPECT_EQ(mismatches, 0u) << "of " << rays_checked << " rays";
    EXPECT_GT(rays_checked, 10000u);
}

TEST(TraceCameraContract, SizeMismatchThrows) {
    const Scene scene = load_scene(kAssets + "/gltf/Duck/glTF-Binary/Duck.glb");
    RenderSettings rs;
    rs.width = 8;
    rs.progress = false;
    const Renderer renderer(scene, rs);
    const WhittedIntegrator integrator(renderer.view(), renderer.accelerator(), rs.integrator);
    std::vector<Ray> rays(4);
    std::vector<Color> radiance(3);
    std::vector<PrimaryInfo> primary(2);
    RayCounters rc;
    EXPECT_ANY_THROW(integrator.trace_camera(rays, radiance, rc));
    radiance.resize(4);
    EXPECT_ANY_THROW(integrator.trace_camera(rays, radiance, rc, {}, primary));
}

}  // namespace
}  // namespace whitted
