// Directions at a surface: mirror reflection and Snell refraction (Whitted 1980), Schlick Fresnel.
#pragma once

#include <cmath>
#include <optional>

#include "core/vecmath.h"

namespace whitted {

/// Mirror direction of the unit vector V (pointing away from the surface) about the unit normal N:
/// R = 2 (N.V) N - V.
inline Vec3f reflect(const Vec3f& V, const Vec3f& N) { return N * (2.f * dot(N, V)) - V; }

/// Refracted direction for unit incident direction I (travelling toward the surface), unit normal
/// N on the incident side (dot(I, N) < 0) and eta = n_incident / n_transmitted, written into T;
/// false on total internal reflection. The renderer's form: an optional returned and copied out
/// stalled on reading back its narrower stores. The optional form below returns nothing instead.
inline bool refract(const Vec3f& I, const Vec3f& N, float eta, Vec3f& T) {
    float cos_i = -dot(N, I);
    float sin2_t = eta * eta * std::max(0.f, 1.f - cos_i * cos_i);
    if (sin2_t >= 1.f) return false;  // total internal reflection
    float cos_t = std::sqrt(1.f - sin2_t);
    T = normalize(I * eta + N * (eta * cos_i - cos_t));
    return true;
}
inline std::optional<Vec3f> refract(const Vec3f& I, const Vec3f& N, float eta) {
    Vec3f T;
    if (!refract(I, N, eta, T)) return std::nullopt;
    return T;
}

/// Direction of the mirror ray at a surface seen from unit V (toward the viewer): V reflected about
/// the shading normal N, or about the geometric normal Ng where N would send it under the surface
/// (N and Ng on the viewer's side). Unit length.
inline Vec3f mirror_direction(const Vec3f& V, const Vec3f& N, const Vec3f& Ng) {
    Vec3f R = reflect(V, N);
    if (dot(R, Ng) <= 0.f) R = reflect(V, Ng);
    return normalize(R);
}

/// Direction of the transmitted ray for unit incident direction I at a surface with shading
/// normal N and geometric normal Ng on the incident side: straight on through a thin-walled
/// surface, else Snell refraction with eta = n_incident / n_transmitted. Nothing on total
/// internal reflection, or where the refracted ray would not cross the geometric surface (then
/// the transmitted weight goes to reflection). Written into T (false: nothing), as refract's form.
inline bool transmitted_direction(const Vec3f& I, const Vec3f& N, const Vec3f& Ng, float eta, bool thin, Vec3f& T) {
    if (thin) {
        T = I;
        return true;
    }
    return refract(I, N, eta, T) && dot(T, Ng) < 0.f;
}
inline std::optional<Vec3f> transmitted_direction(const Vec3f& I, const Vec3f& N, const Vec3f& Ng, float eta,
                                                  bool thin) {
    Vec3f T;
    if (!transmitted_direction(I, N, Ng, eta, thin, T)) return std::nullopt;
    return T;
}

/// Schlick's approximation of the Fresnel reflectance for normal-incidence reflectance f0.
inline Color schlick(const Color& f0, float cos_theta) {
    float c = std::clamp(1.f - cos_theta, 0.f, 1.f);
    float c5 = c * c * c * c * c;
    return f0 + (Color(1.f) - f0) * c5;
}

/// Whitted's (1980) mirror and transmission weights with the Fresnel option (--fresnel): the mirror
/// weight kr follows Schlick's F(theta) of the normal-incidence reflectance ks, and transmission
/// takes what is left, kt (1 - F) / (1 - ks). `cos_v` = N.V clamped to [0, 1].
struct FresnelWeights {
    Color kr, kt;
};
inline FresnelWeights schlick_weights(const Color& ks, const Color& kr, const Color& kt, float cos_v) {
    const Color F = schlick(ks, cos_v);
    FresnelWeights w;
    for (int i = 0; i < 3; ++i) {
        w.kr[i] = ks[i] > 0.f ? kr[i] * F[i] / ks[i] : 0.f;
        w.kt[i] = ks[i] < 1.f ? kt[i] * (1.f - F[i]) / (1.f - ks[i]) : 0.f;
    }
    return w;
}

/// The weights of the reflected and refracted rays at a hit: kr and kt as given, or Schlick-weighted
/// (schlick_weights) with the Fresnel option. The integrator and the stress suite's energy bound
/// both take them from here.
inline FresnelWeights secondary_weights(const Color& ks, const Color& kr, const Color& kt, float cos_v, bool fresnel) {
    return fresnel ? schlick_weights(ks, kr, kt, cos_v) : FresnelWeights{kr, kt};
}

}  // namespace whitted
