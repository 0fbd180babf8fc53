// Fast frames (issue 42): a scene loaded once and posed in place per frame (SceneAnimator), its
// renderer brought up to date (Renderer::update: the accelerator refit where the backend can),
// renders every frame bit for bit as a scene loaded at that time with a renderer built from scratch.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "importers/scene_loader.h"
#include "integrator/render.h"

namespace whitted {
namespace {

const std::string kAssets = WHITTED_ASSETS_DIR;

ImportOptions at_time(double t) {
    ImportOptions o;
    o.time = t;
    o.no_environment = true;  // the default light: fast, and the geometry is what is tested
    return o;
}

RenderSettings small(const std::string& accel) {
    RenderSettings rs;
    rs.width = 48;
    rs.height = 40;
    rs.accel = accel;
    rs.progress = false;
    rs.aovs = AovSet{true, true, true, true, true, true};
    return rs;
}

bool same_pixels(const Film& a, const Film& b) {
    return a.beauty.size() == b.beauty.size() &&
           std::memcmp(a.beauty.data(), b.beauty.data(), a.beauty.size() * sizeof(Color)) == 0 &&
           std::memcmp(a.depth.data(), b.depth.data(), a.depth.size() * sizeof(float)) == 0 &&
           std::memcmp(a.normal.data(), b.normal.data(), a.normal.size() * sizeof(Vec3f)) == 0;
}

/// The sequence's frames against separate loads, for each accelerator; the camera is fixed (the
/// default one of the first frame, as a file's camera would be) so that only the animation moves.
/// Returns how many frames the accelerator was refit for.
int check_frames(const std::string& file, const std::vector<double>& times, const std::string& accel) {
    AnimatedScene a = load_animated_scene(file, at_time(times.front()));
    const Camera camera = a.scene.cameras.at(0);
    Renderer sequence(a.scene, small(accel));
    int refits = 0;
    for (size_t k = 0; k < times.size(); ++k) {
        SCOPED_TRACE(file + " with " + accel + " at t=" + std::to_string(times[k]));
        if (k > 0) {
            SceneUpdate u = a.animator->pose(a.scene, times[k]);
            EXPECT_FALSE(u.reloaded);
            a.scene.cameras[0] = camera;
            refits += sequence.update(u).refit;
        }
        Scene separate = load_scene(file, at_time(times[k]));
        separate.cameras[0] = camera;
        const Renderer fresh(separate, small(accel));
        EXPECT_TRUE(same_pixels(sequence.render(), fresh.render()));
        // The refit structure against one built from scratch over the same posed scene.
        const Renderer rebuilt(a.scene, small(accel));
        EXPECT_TRUE(same_pixels(sequence.render(), rebuilt.render()));
    }
    return refits;
}

TEST(AnimatedFrames, SkinnedSequenceEqualsSeparateLoads) {
    const std::string man = kAssets + "/gltf/CesiumMan/glTF-Binary/CesiumMan.glb";
    const std::string skin = kAssets + "/gltf/SimpleSkin/glTF/SimpleSkin.gltf";
    for (const std::string accel : {"embree", "bvh", "bvh:precision=double", "grid"}) {
        const int refits = check_frames(man, {0.0, 0.4, 0.9, 0.4}, accel);
        if (accel == "embree") {
            EXPECT_EQ(refits, 3);  // RTC_BUILD_QUALITY_REFIT
        }
        check_frames(skin, {0.0, 1.25, 3.5}, accel);
    }
}

TEST(AnimatedFrames, MorphedAndRigidSequencesEqualSeparateLoads) {
    for (const std::string accel : {"embree", "bvh"}) {
        check_frames(kAssets + "/gltf/SimpleMorph/glTF/SimpleMorph.gltf", {0.0, 1.0, 2.5}, accel);
        check_frames(kAssets + "/gltf/AnimatedTriangle/glTF/AnimatedTriangle.gltf", {0.0, 0.3, 0.8}, accel);
    }
}

// Only what moves is in the update: the skinned mesh of CesiumMan (no rigid motion), the rotating
// node of AnimatedTriangle (no deformation), nothing for a static file.
TEST(AnimatedFrames, UpdateNamesWhatMoves) {
    AnimatedScene man = load_animated_scene(kAssets + "/gltf/CesiumMan/glTF-Binary/CesiumMan.glb", at_time(0.0));
    ASSERT_EQ(man.scene.meshes.size(), 1u);
    EXPECT_TRUE(man.scene.meshes[0].deforming);
    const Vec3f* vertices = man.scene.meshes[0].positions.data();
    const Vec3f before = vertices[0];
    SceneUpdate u = man.animator->pose(man.scene, 0.5);
    EXPECT_EQ(u.meshes, std::vector<uint32_t>{0});
    EXPECT_TRUE(u.instances.empty());
    EXPECT_EQ(man.scene.meshes[0].positions.data(), vertices);  // in place: Embree shares the array
    EXPECT_NE(vertices[0], before);
    EXPECT_EQ(man.scene.time, 0.5);

    AnimatedScene tri =
        load_animated_scene(kAssets + "/gltf/AnimatedTriangle/glTF/AnimatedTriangle.gltf", at_time(0.0));
    ASSERT_EQ(tri.scene.instances.size(), 1u);
    EXPECT_TRUE(tri.scene.instances[0].moving);
    EXPECT_FALSE(tri.scene.meshes[0].deforming);
    u = tri.animator->pose(tri.scene, 0.25);
    EXPECT_TRUE(u.meshes.empty());
    EXPECT_EQ(u.instances, std::vector<uint32_t>{0});

    AnimatedScene box = load_animated_scene(kAssets + "/gltf/Box/glTF/Box.gltf", at_time(0.0));
    EXPECT_FALSE(box.scene.instances[0].moving);
    u = box.animator->pose(box.scene, 1.0);
    EXPECT_FALSE(u.geometry());
}

}  // namespace
}  // namespace whitted
