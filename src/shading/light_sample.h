// What a punctual light delivers to a point: direction, distance, fat (attenuation) and spot cone.
#pragma once

#include <cmath>

#include "scene/scene.h"

namespace whitted {

struct LightSample {
    Vec3f L;                 ///< unit direction from the point toward the light
    float distance = 0.f;    ///< to the light; infinite for directional lights
    Color intensity{0.f};    ///< Is * fat * spot: what reaches the point before shadowing
};

/// Distance attenuation `fat`: inverse square with glTF's smooth range window
/// (KHR_lights_punctual recommendation), the classic min(1, 1/(c1 + c2 d + c3 d^2)), or none.
inline float light_attenuation(const Light& light, float d) {
    switch (light.attenuation) {
        case Attenuation::None: return 1.f;
        case Attenuation::Classic: {
            float denom = light.classic_c.x + light.classic_c.y * d + light.classic_c.z * d * d;
            return denom > 0.f ? std::min(1.f, 1.f / denom) : 1.f;
        }
        case Attenuation::InverseSquare:
        default: {
            float fat = 1.f / std::max(d * d, 1e-12f);
            if (light.range > 0.f) {
                float r = d / light.range;
                float w = std::clamp(1.f - r * r * r * r, 0.f, 1.f);
                fat *= w * w;
            }
            return fat;
        }
    }
}

/// Spot cone falloff: 1 inside the inner cone, 0 outside the outer, smooth in between (glTF).
inline float spot_falloff(const Light& light, const Vec3f& L) {
    float cos_outer = std::cos(light.outer_cone);
    float cos_inner = std::cos(light.inner_cone);
    float cd = dot(Vec3f(light.direction), -L);
    if (cd <= cos_outer) return 0.f;
    if (cd >= cos_inner || cos_inner <= cos_outer) return 1.f;
    float t = (cd - cos_outer) / (cos_inner - cos_outer);
    return t * t;
}

/// The light arriving at p from `light` (before the shadow factor s).
inline LightSample sample_light(const Light& light, const Vec3f& p) {
    LightSample s;
    Color is = light.color * light.intensity;
    if (light.type == LightType::Directional) {
        s.L = normalize(-Vec3f(light.direction));
        s.distance = kInfinity;
        s.intensity = is;
        return s;
    }
    Vec3f d = Vec3f(light.position) - p;
    s.distance = length(d);
    s.L = s.distance > 0.f ? d / s.distance : Vec3f(0.f, 0.f, 1.f);
    float fat = light_attenuation(light, s.distance);
    float spot = light.type == LightType::Spot ? spot_falloff(light, s.L) : 1.f;
    s.intensity = is * (fat * spot);
    return s;
}

}  // namespace whitted
