// The local model's term for one light at one point, before the light's intensity and shadow
// factor: kd (N.L) + ks (N.H)^n (Whitted 1980, with Blinn's half vector).
#pragma once

#include <algorithm>
#include <cmath>

#include "renderer/core/vecmath.h"
#include "renderer/scene/scene.h"

namespace whitted {

/// Below this, n (1 - N.H) makes the highlight invisible: x^n <= e^(-n (1 - x)) (as ln x <= x - 1),
/// and e^-17 < 2^-24 of ks, so its pow is not evaluated.
constexpr float kHighlightCutoff = 17.f;

/// Share of a light's specular reflection the highlight ks (N.H)^n carries at normal incidence:
/// normalised Blinn-Phong is (n + 8) / (8 pi) (N.H)^n (Akenine-Moller et al., Real-Time
/// Rendering), so the unnormalised lobe brings 8 / (n + 8) of it (0.9 at n = 1, 0.08 % at 10000).
inline float highlight_share(float n) { return 8.f / (std::max(n, 1.f) + 8.f); }

/// kd (N.L) + ks (N.H)^n for unit N, L (toward the light) and V (toward the viewer), n_dot_l = N.L > 0.
inline Color local_term(const WhittedCoeffs& c, const Vec3f& N, const Vec3f& L, const Vec3f& V, float n_dot_l) {
    Color term = c.kd * n_dot_l;
    if (!is_black(c.ks)) {
        const Vec3f H = normalize(L + V);
        const float n_dot_h = std::max(0.f, dot(N, H));
        if (c.n * (1.f - n_dot_h) < kHighlightCutoff) term += c.ks * std::pow(n_dot_h, c.n);
    }
    return term;
}

}  // namespace whitted
