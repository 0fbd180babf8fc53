// Grazing angles and refraction (docs/numerical-stability.md, section 4). Mirrors (planes,
// meshes, spheres) hit at incidence angles up to 89.99 degrees; slabs of ior 1.0 (invisible),
// 1.0001, 1.5 and 2.4; total internal reflection at and around the critical angle; nested and
// touching dielectrics.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "benchmarks/stability_probes.h"
#include "importers/scene_loader.h"
#include "core/ray_offset.h"
#include "integrator/whitted_integrator.h"
#include "scene/scene_builder.h"
#include "shading/optics.h"

namespace whitted::stress {
namespace {

const double kAnglesDeg[] = {0.0, 30.0, 60.0, 80.0, 89.0, 89.9, 89.99};

Color render_one(const Scene& scene, const std::string& accel = "bvh", int max_depth = 5) {
    RenderSettings rs;
    rs.width = rs.height = 1;
    rs.threads = 1;
    rs.accel = accel;
    rs.integrator.max_depth = max_depth;
    rs.integrator.ambient = Color(0.f);
    const Renderer r(scene, rs);
    return r.render().beauty[0];
}

WhittedCoeffs mirror() {
    WhittedCoeffs c;
    c.kr = Color(0.5f);  // a miss would show E (the sky) or 0 (background), a reflection 0.5 E
    return c;
}

WhittedCoeffs emitter(Color e) {
    WhittedCoeffs c;
    c.emission = e;
    return c;
}

Plane plane(Vec3d point, Vec3d normal, uint32_t material) {
    Plane p;
    p.point = point;
    p.normal = normalize(normal);
    p.u_axis = std::fabs(p.normal.x) < 0.9 ? normalize(cross(p.normal, Vec3d{1, 0, 0})) : Vec3d{0, 0, 1};
    p.material = material;
    return p;
}

// A mirror (analytic plane, mesh quad or analytic sphere) seen at incidence theta by an
// orthographic camera; the reflected ray must reach the emitter (an emissive ceiling plane or an
// enclosing emissive sphere): pixel = 0.5 x emission exactly. A self-intersecting reflection, a missed
// grazing hit or a NaN would show.
TEST(StressGrazing, MirrorsUpToEightyNineNinetyNineDegrees) {
    const Color E{0.25f, 0.5f, 1.f};
    for (double scale : {1e-3, 1.0, 1e3})
        for (int kind = 0; kind < 3; ++kind)
            for (double deg : kAnglesDeg)
                for (const char* accel : {"bvh", "embree"}) {
                    const double th = deg * kPiD / 180.0;
                    Scene s;
                    const uint32_t m = add_classic_material(s, mirror(), "mirror");
                    const uint32_t e = add_classic_material(s, emitter(E), "sky");
                    Vec3d hit, normal;
                    if (kind == 2) {
                        // Sphere of radius `scale` at the origin, hit at incidence theta.
                        Sphere sp;
                        sp.radius = scale;
                        sp.material = m;
                        s.spheres.push_back(sp);
                        Sphere sky;
                        sky.radius = 1e4 * scale;
                        sky.material = e;
                        s.spheres.push_back(sky);
                        normal = {0, std::cos(th), std::sin(th)};
                        hit = normal * scale;
                    } else {
                        normal = {0, 1, 0};
                        hit = {0, 0, 0};
                        if (kind == 0) {
                            s.planes.push_back(plane({0, 0, 0}, {0, 1, 0}, m));
                        } else {
                            const float h = float(1e5 * scale);
                            add_mesh(s, make_quad({-h, 0, h}, {h, 0, h}, {h, 0, -h}, {-h, 0, -h}, m));
                        }
                        s.planes.push_back(plane({0, scale, 0}, {0, -1, 0}, e));
                    }
                    // Incoming direction at angle theta to the normal, in the plane of normal and +z.
                    const Vec3d tangent = normalize(cross(cross(normal, Vec3d{0, 0, 1}), normal));
                    const Vec3d t_dir = std::fabs(deg) < 1e-9 ? Vec3d{0, 0, 1} : tangent;
                    const Vec3d dir = normalize(t_dir * std::sin(th) - normal * std::cos(th));
                    s.cameras.push_back(make_camera(CameraType::Orthographic, hit - dir * (0.5 * scale), dir,
                                                    std::fabs(dir.y) > 0.9 ? Vec3d{0, 0, 1} : Vec3d{0, 1, 0}, 1e-9 * scale));
                    const Color c = render_one(s, accel);
                    const std::string what = std::string(accel) + " kind " + std::to_string(kind) + " scale " +
                                             std::to_string(scale) + " at " + std::to_string(deg) + " deg";
                    EXPECT_NEAR(c.x, 0.5f * E.x, 1e-6f) << what;
                    EXPECT_NEAR(c.y, 0.5f * E.y, 1e-6f) << what;
                    EXPECT_NEAR(c.z, 0.5f * E.z, 1e-6f) << what;
                }
}

/// A slab (closed box, non-thin glass: kt = 1, kr = 0) between a perspective camera and a
/// checker background; `tilt` rotates it so rays meet it from normal to grazing incidence.
/// `swap` adds the two halves of a split slab in the other order.
Scene slab_scene(float ior, bool with_slab, bool split_in_two, float gap = 0.f, bool swap = false) {
    Scene s;
    Texture checker;
    checker.kind = TextureKind::Checker;
    checker.checker.color_a = Color(0.9f, 0.8f, 0.1f);
    checker.checker.color_b = Color(0.1f, 0.2f, 0.7f);
    checker.checker.size = 0.25f;
    checker.checker.world_space = true;
    s.textures.push_back(checker);
    WhittedCoeffs floor;
    floor.kd = floor.ka = Color(1.f);
    const uint32_t fm = add_classic_material(s, floor, "floor");
    s.materials[fm].classic_color_texture.texture = 0;
    s.planes.push_back(plane({0, 0, -3}, {0, 0.3, 1}, fm));
    WhittedCoeffs glass;
    glass.kt = Color(1.f);
    glass.ior = ior;
    glass.thin = false;
    const uint32_t gm = add_classic_material(s, glass, "glass");
    const Mat4d tilt = Mat4d::rotate(0.0, std::sin(0.6), 0.0, std::cos(0.6));  // 69 degrees about y
    if (with_slab) {
        if (split_in_two) {
            // Two slabs touching along z = 0 (coincident faces): optically one slab.
            const Mesh lower = make_box({-1, -1, -0.2f}, {1, 1, 0}, gm);
            const Mesh upper = make_box({-1, -1, gap}, {1, 1, 0.2f + gap}, gm);
            add_mesh(s, swap ? upper : lower, tilt);
            add_mesh(s, swap ? lower : upper, tilt);
        } else {
            add_mesh(s, make_box({-1, -1, -0.2f}, {1, 1, 0.2f}, gm), tilt);
        }
    }
    s.lights.push_back(point_light({0, 3, 3}, 10.f));
    s.cameras.push_back(make_camera(CameraType::Perspective, {0.2, 0.1, 4}, {0, 0, -1}, {0, 1, 0}, 0.9));
    return s;
}

/// Deep enough that truncating the ray tree cannot explain a difference (each extra interface
/// costs one level).
Film render_film(const Scene& s, const char* accel) {
    RenderSettings rs;
    rs.width = 96;
    rs.height = 72;
    rs.accel = accel;
    rs.integrator.max_depth = 40;
    return Renderer(s, rs).render();
}

// ior 1.0: every refraction continues straight, so the slab (kr = 0) is invisible: the image
// equals the one without it, except pixels whose ray passes within rounding of a checker edge.
TEST(StressRefraction, SlabWithIorOneIsInvisible) {
    for (const char* accel : {"bvh", "embree"}) {
        const Film without = render_film(slab_scene(1.f, false, false), accel);
        const Film with = render_film(slab_scene(1.f, true, false), accel);
        size_t bad = 0;
        max_abs_diff(with, without, 1e-4, &bad);
        EXPECT_LE(bad, with.beauty.size() / 500) << accel;
        EXPECT_GE(psnr(with, without), 45.0) << accel;
    }
}

// The integrator's refraction (src/shading/optics.h refract, oriented as in shade()) through the two
// faces of a parallel slab: the ray leaves parallel to how it entered, displaced by Snell's law.
TEST(StressRefraction, ParallelSlabExitDirectionAndShift) {
    for (float ior : {1.0f, 1.0001f, 1.5f, 2.4f})
        for (double deg : kAnglesDeg) {
            const double th = deg * kPiD / 180.0;
            const Vec3f I = Vec3f(Vec3d(std::sin(th), 0.0, -std::cos(th)));
            const Vec3f N{0, 0, 1};  // entry face, facing the incoming ray
            const auto T = refract(I, N, 1.f / ior);
            ASSERT_TRUE(T.has_value()) << ior << " " << deg;
            // Exit face: the geometric normal faces away from the ray inside, so shade() flips it.
            const auto O = refract(*T, N, ior);
            const std::string what = "ior " + std::to_string(ior) + " at " + std::to_string(deg) + " deg";
            // Float directions carry the incidence angle in the normal component; the exit cosine
            // is a difference 1 - sin^2 of rounded values, so errors grow like eps / cos^2.
            const double cos2 = std::cos(th) * std::cos(th);
            if (deg <= 89.9) {
                ASSERT_TRUE(O.has_value()) << what << ": total internal reflection on exit";
                EXPECT_LE(length(Vec3d(*O) - Vec3d(I)), 1e-6 + 4e-8 / cos2) << what;
                // Lateral shift through thickness 1: sin(th - th_t) / cos(th_t).
                const double tht = std::asin(std::sin(th) / double(ior));
                const double shift_ref = std::sin(th - tht) / std::cos(tht);
                const double shift = (std::tan(th) - double(T->x) / -double(T->z)) * std::cos(th);
                EXPECT_NEAR(shift, shift_ref, 1e-6 + 4e-8 / cos2) << what;
            } else if (O) {
                EXPECT_TRUE(is_finite(*O)) << what;
                EXPECT_NEAR(length(*O), 1.f, 1e-5f) << what;
            }
        }
}

// Total internal reflection exactly at and around the critical angle: refract() decides
// consistently (transmits below, reflects above, at 1e-6 rad either side) and never returns a
// NaN or a non-unit direction, exactly at the critical angle included.
TEST(StressRefraction, TotalInternalReflectionAroundCriticalAngle) {
    for (float ior : {1.0001f, 1.5f, 2.4f}) {
        const double crit = std::asin(1.0 / double(ior));
        for (double delta : {-1e-3, -1e-5, -1e-6, 0.0, 1e-6, 1e-5, 1e-3}) {
            const double th = crit + delta;
            const Vec3f I = Vec3f(Vec3d(std::sin(th), 0.0, -std::cos(th)));
            const auto O = refract(I, Vec3f{0, 0, 1}, ior);  // inside the dense medium, leaving
            const std::string what = "ior " + std::to_string(ior) + " crit " + std::to_string(delta);
            // Float directions resolve the angle to ~1e-7 rad; the decision is exact beyond 1e-5.
            if (delta <= -1e-5) {
                EXPECT_TRUE(O.has_value()) << what;
            }
            if (delta >= 1e-5) {
                EXPECT_FALSE(O.has_value()) << what;
            }
            if (O) {
                EXPECT_TRUE(is_finite(*O)) << what;
                EXPECT_NEAR(length(*O), 1.f, 1e-5f) << what;
                EXPECT_LE(O->z, 0.f) << what;
            }
        }
    }
}

// Nested dielectrics: a glass sphere containing a sphere of relative ior 1.0 (kt 1, kr 0) looks
// exactly like the glass sphere alone (scene files author nested media by relative ior,
// docs/materials.md). Touching dielectrics: two glass slabs sharing a face must look like one
// slab of the combined thickness.
TEST(StressRefraction, NestedRelativeIorOneIsInvisible) {
    auto scene = [](bool inner) {
        Scene s;
        WhittedCoeffs glass;
        glass.kt = Color(0.9f);
        glass.kr = Color(0.1f);
        glass.ior = 1.5f;
        glass.thin = false;
        WhittedCoeffs same;
        same.kt = Color(1.f);
        same.ior = 1.f;
        same.thin = false;
        Sphere a;
        a.radius = 1.0;
        a.material = add_classic_material(s, glass, "glass");
        s.spheres.push_back(a);
        if (inner) {
            Sphere b;
            b.radius = 0.5;
            b.center = {0.1, 0.05, 0};
            b.material = add_classic_material(s, same, "same medium");
            s.spheres.push_back(b);
        }
        WhittedCoeffs floor;
        floor.kd = floor.ka = Color(0.8f, 0.5f, 0.3f);
        s.planes.push_back(plane({0, -1.5, 0}, {0, 1, 0}, add_classic_material(s, floor, "floor")));
        s.lights.push_back(point_light({2, 4, 3}, 20.f));
        s.cameras.push_back(make_camera(CameraType::Perspective, {0, 0.5, 4}, {0, -0.1, -1}, {0, 1, 0}, 0.7));
        return s;
    };
    for (const char* accel : {"bvh", "embree"}) {
        const Film with = render_film(scene(true), accel), without = render_film(scene(false), accel);
        size_t bad = 0;
        max_abs_diff(with, without, 1e-3, &bad);
        EXPECT_LE(bad, with.beauty.size() / 200) << accel;
        EXPECT_GE(psnr(with, without), 40.0) << accel;
    }
}

// Two slabs separated by a gap larger than the ray offset act as one slab (the gap's own shift
// is below the tolerance).
TEST(StressRefraction, SlabsWithAGapActAsOne) {
    for (float gap : {1e-3f, 1e-5f})
        for (const char* accel : {"bvh", "embree"}) {
            const Film one = render_film(slab_scene(1.5f, true, false), accel);
            const Film two = render_film(slab_scene(1.5f, true, true, gap), accel);
            size_t bad = 0;
            max_abs_diff(two, one, 0.02, &bad);
            EXPECT_LE(bad, one.beauty.size() / 100) << accel << " gap " << gap;
        }
}

// Touching dielectrics: two slabs sharing a face (coincident, opposite-facing surfaces) act as one
// slab of the combined thickness. Without the integrator's contact handling (DielectricContacts)
// the ray leaving the first slab starts past the shared plane inside the second, never meets its
// face, and crosses it bent as if it had left into air. Which of the two coincident faces the
// accelerator reports is arbitrary, so the slabs are also added in the other order.
TEST(StressRefraction, TouchingSlabsActAsOne) {
    for (const bool swap : {false, true})
        for (const char* accel : {"bvh", "embree"}) {
            const Film one = render_film(slab_scene(1.5f, true, false), accel);
            const Film two = render_film(slab_scene(1.5f, true, true, 0.f, swap), accel);
            size_t bad = 0;
            max_abs_diff(two, one, 0.02, &bad);
            RecordProperty(std::string("bad_pixels_") + accel + (swap ? "_swapped" : ""), std::to_string(bad));
            EXPECT_LE(bad, one.beauty.size() / 100) << accel << (swap ? " swapped" : "") << ": " << bad << " of "
                                                    << one.beauty.size();
        }
}

// The same with absorbing glass (Beer-Lambert inside both slabs) and at a scale and distance where
// the shared face is far from the origin: the contact search scales with the hit point's ulp.
TEST(StressRefraction, TouchingAbsorbingSlabsActAsOneFarFromTheOrigin) {
    for (const double scale : {1.0, 1e3})
        for (const double translation : {0.0, 1e4}) {
            auto place = [&](bool split) {
                Scene s = slab_scene(1.5f, true, split);
                s.materials[1].classic.absorption = Color(0.3f, 1.f, 2.f);  // 0: floor, 1: glass
                transform_scene(s, scale, translation);
                return s;
            };
            const Film one = render_film(place(false), "embree");
            const Film two = render_film(place(true), "embree");
            size_t bad = 0;
            max_abs_diff(two, one, 0.02, &bad);
            RecordProperty("bad_pixels_s" + std::to_string(int(scale)) + "_t" + std::to_string(int(translation)),
                           std::to_string(bad));
            EXPECT_LE(bad, one.beauty.size() / 100) << "scale " << scale << " at " << translation << ": " << bad;
        }
}

// The contact search is a query like any other: the image is the same for any thread count.
TEST(StressRefraction, TouchingSlabsIdenticalForAnyThreadCount) {
    RenderSettings rs;
    rs.width = 96;
    rs.height = 72;
    rs.accel = "embree";
    rs.integrator.max_depth = 40;
    rs.threads = 1;
    const Scene s = slab_scene(1.5f, true, true);
    const Film a = Renderer(s, rs).render();
    rs.threads = 2;
    const Film b = Renderer(s, rs).render();
    EXPECT_EQ(max_abs_diff(a, b, 0.0, nullptr), 0.0);
}

// The contact search costs nothing where no dielectrics touch: the bundled scenes (whitted1980's
// hollow sphere is two concentric spheres 0.05 apart) and slabs far apart get no structure; the
// touching slabs do (meshes are tested by their bounds, which is conservative: the tilted slabs
// with a 1e-3 gap still get the search, and find nothing).
TEST(StressRefraction, ContactSearchOnlyWhereDielectricsTouch) {
    auto engaged = [](const Scene& s) {
        RenderSettings rs;
        const Renderer r(s, rs);
        return WhittedIntegrator(r.view(), r.accelerator(), rs.integrator).handles_touching_dielectrics();
    };
    for (const char* name : {"whitted1980.json", "glass_mirror_room.json", "transparent_shadows.json", "default.glb"})
        EXPECT_FALSE(engaged(load_scene(std::string(WHITTED_ASSETS_DIR) + "/scenes/" + name))) << name;
    EXPECT_FALSE(engaged(slab_scene(1.5f, true, true, 3.f)));
    EXPECT_TRUE(engaged(slab_scene(1.5f, true, true)));
    // Spheres: tested exactly (external and internal tangency), not by bounds.
    auto spheres = [](Vec3d c2, double r2) {
        Scene s;
        WhittedCoeffs glass;
        glass.kt = Color(1.f);
        glass.thin = false;
        const uint32_t m = add_classic_material(s, glass, "glass");
        Sphere a, b;
        a.material = b.material = m;
        b.center = c2;
        b.radius = r2;
        s.spheres = {a, b};
        s.cameras.push_back(make_camera(CameraType::Perspective, {0, 0, 5}, {0, 0, -1}, {0, 1, 0}, 0.9));
        return s;
    };
    EXPECT_TRUE(engaged(spheres({2, 0, 0}, 1.0)));     // touching outside
    EXPECT_TRUE(engaged(spheres({0.5, 0, 0}, 0.5)));   // touching inside
    EXPECT_FALSE(engaged(spheres({2.1, 0, 0}, 1.0)));  // apart
    EXPECT_FALSE(engaged(spheres({0, 0, 0}, 0.95)));   // concentric shell, 0.05 apart
}

}  // namespace
}  // namespace whitted::stress
