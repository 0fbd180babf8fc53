// Small scenes under an environment, shared by the environment render tests.
#pragma once

#include <gtest/gtest.h>

#include <memory>

#include "importers/scene_loader.h"
#include "integrator/render.h"
#include "scene/scene_builder.h"

namespace whitted::test {

/// A lat-long of constant radiance L.
inline Environment constant_environment(Color L) {
    auto image = std::make_shared<EnvironmentImage>();
    image->name = "constant";
    image->width = 64;
    image->height = 32;
    image->texels.assign(64 * 32, L);
    Environment env;
    env.image = image;
    return env;
}

/// Gives `s` the environment `env`, split into at most `env_lights` lights as `render` does.
inline void light_with(Scene& s, const Environment& env, int env_lights) {
    s.environment = env;
    ImportOptions io;
    io.environment_lights = env_lights;
    setup_environment(s, io);
}

/// A glTF metal of base colour `base` and roughness `roughness`.
inline Material gltf_metal(Color base, float roughness) {
    Material m;
    m.model = MaterialModel::GltfPbr;
    m.base_color = Vec4f(base, 1.f);
    m.metallic = 1.f;
    m.roughness = roughness;
    return m;
}

/// A square render of `size` pixels on one thread.
inline Film render_square(const Scene& scene, const IntegratorSettings& integrator = {}, int size = 32) {
    RenderSettings rs;
    rs.width = rs.height = size;
    rs.threads = 1;
    rs.integrator = integrator;
    return Renderer(scene, rs).render();
}

inline void expect_near_rel(const Color& got, const Color& want, float rel) {
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(got[k], want[k], rel * want[k]) << "channel " << k;
}

}  // namespace whitted::test
