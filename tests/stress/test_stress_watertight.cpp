// Watertightness (docs/numerical-stability.md, section 3). Rays from inside closed meshes aimed
// at vertices, edge midpoints and random points must all hit: 0 leaks for every in-house backend
// (Woop et al. 2013 with the double fallback); Embree's count is recorded, with and without
// RTC_SCENE_FLAG_ROBUST.
// `whitted bench stability` runs 10M rays per backend and mesh.
#include <gtest/gtest.h>

#include <string>

#include "benchmarks/stability_probes.h"
#include "importers/scene_loader.h"

namespace whitted::stress {
namespace {

struct ClosedMesh {
    std::string name;
    Mesh mesh;
};

std::vector<ClosedMesh> closed_meshes() {
    std::vector<ClosedMesh> out;
    out.push_back({"sphere 48x96", make_closed_sphere(48, 96, false)});
    out.push_back({"cube 8x8", make_closed_cube(8)});
    // A real closed asset: the Duck (glTF sample model), 4212 triangles.
    const Scene duck = load_scene(WHITTED_ASSETS_DIR "/gltf/Duck/glTF-Binary/Duck.glb");
    out.push_back({"Duck.glb", duck.meshes.at(0)});
    return out;
}

TEST(StressWatertight, ClosedMeshesDoNotLeak) {
    for (const ClosedMesh& cm : closed_meshes()) {
        ASSERT_TRUE(is_closed_mesh(cm.mesh)) << cm.name;
        Vec3f inside;
        float radius = 0.f;
        ASSERT_TRUE(find_inside_point(cm.mesh, inside, radius)) << cm.name;
        for (const auto& [scale, translation] : {std::pair{1.0, 0.0}, std::pair{1e-3, 10.0}, std::pair{1e3, 1e5}}) {
            for (const char* accel : {"bvh", "bvh:precision=double", "kdop", "grid", "octree", "brute", "embree"})
                for (bool robust : {false, true}) {
                    if (robust && std::string(accel) != "embree") continue;
                    WatertightConfig c;
                    c.accel = accel;
                    c.robust = robust;
                    c.rays = std::string(accel) == "brute" ? 6000 : 30000;
                    c.scale = scale;
                    c.translation = translation;
                    const WatertightResult r = probe_watertight(cm.mesh, inside, radius, c);
                    const uint64_t leaks = r.leaks[0] + r.leaks[1] + r.leaks[2];
                    const std::string what = cm.name + " " + accel + (robust ? " robust" : "") +
                                             " s=" + std::to_string(scale) + " t=" + std::to_string(translation);
                    if (std::string(accel) == "embree") {
                        RecordProperty(what, std::to_string(leaks));  // reported, not asserted
                        continue;
                    }
                    EXPECT_EQ(leaks, 0u) << what << " (vertex " << r.leaks[0] << ", edge " << r.leaks[1]
                                         << ", random " << r.leaks[2] << ")";
                }
        }
    }
}

}  // namespace
}  // namespace whitted::stress
