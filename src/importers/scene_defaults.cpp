// Default camera and light shared by the glTF importer and the scene-file importer.

#include "importers/scene_defaults.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace whitted {

namespace {

// Documented in docs/lights.md and docs/gltf-support.md.
constexpr double kDefaultCameraYfov = 0.8;                               ///< radians (about 45.8 degrees)
constexpr double kDefaultCameraMargin = 1.1;                             ///< bounding sphere fills 1/1.1 of the view
constexpr float kDefaultLightIntensity = 1.f;                            ///< lux (renderer units, docs/lights.md)
const Vec3d kDefaultLightDirection = normalize(Vec3d(0.4, -1.0, -0.6));  ///< travel direction

}  // namespace

void add_default_light(Scene& scene, WarningLog& warnings) {
    Light l;
    l.name = "default light";
    l.type = LightType::Directional;
    l.color = Color(1.f);
    l.intensity = kDefaultLightIntensity;
    l.direction = kDefaultLightDirection;
    l.attenuation = Attenuation::None;
    l.is_default = true;
    scene.lights.push_back(std::move(l));
    warnings.add("default-light", "no lights in the file: added the default light (see docs/lights.md)");
}

/// Perspective camera on +Z, raised 15 degrees, looking at the bounds centre from far enough
/// that the bounding sphere fits the vertical field of view with a 10% margin.
Camera default_camera(const Bounds3d& b, double orbit_degrees) {
    Vec3d center(0.0);
    double radius = 1.0;
    if (!b.empty()) {
        center = b.center();
        radius = 0.5 * length(b.diagonal());
        if (!(radius > 0)) radius = 1.0;
    }
    const double distance = radius / std::sin(kDefaultCameraYfov / 2) * kDefaultCameraMargin;
    const double elevation = 15.0 * std::numbers::pi / 180.0;
    Vec3d to_eye{0.0, std::sin(elevation), std::cos(elevation)};
    if (orbit_degrees != 0.0) {  // turned about +Y through the centre
        const double a = orbit_degrees * std::numbers::pi / 180.0;
        to_eye = {std::sin(a) * to_eye.z, to_eye.y, std::cos(a) * to_eye.z};
    }
    const Vec3d eye = center + to_eye * distance;
    // Camera frame: -Z looks at the centre, +X right, +Y up (glTF convention).
    const Vec3d z = to_eye;
    const Vec3d x = normalize(cross(Vec3d(0, 1, 0), z));
    const Vec3d y = cross(z, x);
    Camera c;
    c.name = "default camera";
    c.type = CameraType::Perspective;
    c.yfov = kDefaultCameraYfov;
    c.aspect = 0.0;
    c.znear = std::max(1e-6, (distance - radius * kDefaultCameraMargin) * 0.1);
    c.zfar = 0.0;
    for (int r = 0; r < 3; ++r) {
        c.world_from_camera(r, 0) = x[r];
        c.world_from_camera(r, 1) = y[r];
        c.world_from_camera(r, 2) = z[r];
        c.world_from_camera(r, 3) = eye[r];
    }
    c.is_default = true;
    return c;
}

void add_default_camera(Scene& scene, WarningLog& warnings) {
    scene.cameras.push_back(default_camera(scene.world_bounds()));
    warnings.add("default-camera", "no cameras in the scene: added a default camera framing the bounds");
}

void add_scene_defaults(Scene& scene, const ImportOptions& options, WarningLog& warnings) {
    if (scene.cameras.empty() && options.add_default_camera) add_default_camera(scene, warnings);
    if (scene.lights.empty() && options.add_default_light) add_default_light(scene, warnings);
}

}  // namespace whitted
