// The local model's term for one light at one point, before the light's intensity and shadow
// factor: kd (N.L) + ks (N.H)^n (Whitted 1980, with Blinn's half vector).
#pragma once

#include <algorithm>
#include <cmath>

#include "core/vecmath.h"
#include "scene/scene.h"

namespace whitted {

/// Below this, n (1 - N.H) makes the highlight invisible: x^n <= e^(-n (1 - x)) (as ln x <= x - 1),
/// and e^-17 < 2^-24 of ks, so its pow is not evaluated.
constexpr float kHighlightCutoff = 17.f;

/// What the highlight ks (N.H)^n of light arriving from every direction of the hemisphere brings, in
/// units of ks, at normal incidence (V = N, so N.H = cos(theta / 2)):
/// (1/pi) integral of (N.H)^n dw = 8 (1 - 2^(-(n + 2) / 2)) / (n + 2). About 8 / (n + 2) for sharp
/// highlights; above 1 for n below 4.6, where the unnormalised lobe reflects more than ks of the
/// light around it (1.72 at n = 1).
inline float highlight_integral(float n) {
    const float m = std::max(n, 1.f) + 2.f;
    return 8.f * (1.f - std::exp2(-0.5f * m)) / m;
}

/// Where the highlight's shape stands for the lobe it replaces: (N.H)^n without N.L departs from
/// the GGX lobe below n = 10 (roughness 0.63), more at grazing views, so there the extracted lights
/// hand their specular reflection back to the prefiltered map, fading out over n = 10 .. 4
/// (roughness 0.63 .. 0.76). Their diffuse light, and its shadows, stay.
inline float environment_highlight_weight(float n) { return std::clamp((n - 4.f) / 6.f, 0.f, 1.f); }

/// Share of an environment's specular reflection the highlights of its extracted lights carry
/// (the glossy term reads the rest from the prefiltered map): at most all of it.
inline float highlight_share(float n) { return std::min(1.f, highlight_integral(n)) * environment_highlight_weight(n); }

/// Scale of the extracted lights' highlights so that they bring highlight_share(n) and no more.
inline float environment_highlight_scale(float n) {
    return std::min(1.f, 1.f / highlight_integral(n)) * environment_highlight_weight(n);
}

/// The highlight's lobe (N.H)^n for N.H = n_dot_h >= 0, and 0 where the cutoff above makes it
/// invisible (the pow is then not evaluated).
inline float highlight_lobe(float n_dot_h, float n) {
    return n * (1.f - n_dot_h) < kHighlightCutoff ? std::pow(n_dot_h, n) : 0.f;
}

/// kd (N.L) + ks (N.H)^n for unit N, L (toward the light) and V (toward the viewer), n_dot_l = N.L > 0.
/// highlight_scale: 1 but for the lights extracted from an environment (environment_highlight_scale);
/// at 0 (a lobe rougher than n = 4, which the prefiltered map carries) the highlight is not evaluated.
inline Color local_term(const WhittedCoeffs& c, const Vec3f& N, const Vec3f& L, const Vec3f& V, float n_dot_l,
                        float highlight_scale = 1.f) {
    Color term = c.kd * n_dot_l;
    if (!is_black(c.ks) && highlight_scale > 0.f) {
        const Vec3f H = normalize(L + V);
        const float n_dot_h = std::max(0.f, dot(N, H));
        if (const float lobe = highlight_lobe(n_dot_h, c.n); lobe > 0.f) term += c.ks * (lobe * highlight_scale);
    }
    return term;
}

}  // namespace whitted
