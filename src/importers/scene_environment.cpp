// The environment step of every import (load_scene): which map, then its light as lights + ambient.
#include <algorithm>
#include <memory>

#include <fmt/format.h>

#include "importers/environment_image.h"
#include "importers/scene_loader.h"
#include "core/log.h"
#include "shading/environment_map.h"

namespace whitted {

void setup_environment(Scene& scene, const ImportOptions& options) {
    if (options.no_environment) {
        scene.environment.reset();
        return;
    }
    if (!options.environment.empty()) {
        std::vector<std::string> warnings;
        const std::string path = resolve_environment_name(options.environment);
        auto image = std::make_shared<EnvironmentImage>(load_environment_image(path, options.max_memory, warnings));
        for (const std::string& w : warnings)
            if (is_bundled_environment(path)) log_info("{}", w);
            else scene.warn(w);
        Environment env;
        env.image = std::move(image);
        scene.environment = std::move(env);
    }
    if (!scene.environment) return;
    Environment& env = *scene.environment;
    if (options.environment_rotation) env.rotation_deg = *options.environment_rotation;
    if (options.environment_exposure) env.exposure_stops = *options.environment_exposure;

    // Its light: the brightest regions as directional lights, the rest as the SH ambient. The
    // lights replace the default light a scene without lights was given. The split reads the
    // full map, so no residual is built for it.
    env.extraction_threshold = kInfinity;
    const EnvironmentMap map(env, 0, EnvironmentMap::Use::SplitOnly);
    const EnvironmentLighting lighting = map.split(std::max(options.environment_lights, 0));
    const size_t before = scene.lights.size();
    std::erase_if(scene.lights, [](const Light& l) { return l.is_default; });
    if (scene.lights.size() != before)  // nor its warning: the environment lights the scene
        std::erase_if(scene.warnings, [](const std::string& w) { return w.find("added the default light") != std::string::npos; });
    for (size_t k = 0; k < lighting.lights.size(); ++k) {
        Light light = to_directional_light(lighting.lights[k], fmt::format("environment light {}", k));
        light.from_environment = true;
        scene.lights.push_back(light);
    }
    env.ambient_sh = lighting.residual_sh;
    env.extraction_threshold = lighting.threshold;  // reflected rays see what the lights leave
}

}  // namespace whitted
