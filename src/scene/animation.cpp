// Keyframe sampling after glTF 2.0 Appendix C, clamping after section 3.11.
#include "scene/animation.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "core/error.h"

namespace whitted {
namespace {

/// Element `e` of key `k`; CubicSpline keys hold three (0 in-tangent, 1 value, 2 out-tangent).
const float* element(const AnimationSampler& s, size_t k, size_t e) {
    const size_t per_key = s.interpolation == Interpolation::CubicSpline ? 3 : 1;
    return s.values.data() + (k * per_key + e) * size_t(s.components);
}

/// The property value of key `k` (for CubicSpline the middle of its three elements).
const float* key_value(const AnimationSampler& s, size_t k) {
    return element(s, k, s.interpolation == Interpolation::CubicSpline ? 1 : 0);
}

/// Scales the quaternion `q` to unit length; one of zero (or non-finite) length becomes the identity.
void normalize_quaternion(double q[4]) {
    const double len = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (!(len > 0.0) || !std::isfinite(len)) {
        q[0] = q[1] = q[2] = 0.0;
        q[3] = 1.0;
        return;
    }
    for (int i = 0; i < 4; ++i) q[i] /= len;
}

/// Spherical linear interpolation from `a` to `b` at `u` in [0, 1], both normalised first, along
/// the shorter arc (Appendix C, "Spherical Linear Interpolation"; Shoemake 1985).
void slerp(const float* a, const float* b, double u, float* out) {
    double q0[4], q1[4];
    for (int i = 0; i < 4; ++i) {
        q0[i] = a[i];
        q1[i] = b[i];
    }
    normalize_quaternion(q0);
    normalize_quaternion(q1);
    // q and -q are the same rotation: take the one nearer to q0 so the path is the short one.
    double d = q0[0] * q1[0] + q0[1] * q1[1] + q0[2] * q1[2] + q0[3] * q1[3];
    if (d < 0.0) {
        for (double& x : q1) x = -x;
        d = -d;
    }
    // Weights sin((1-u)a)/sin(a) and sin(ua)/sin(a); below 1e-4 rad they are 1-u and u to 1e-9,
    // and normalised lerp avoids dividing by sin(a) ~ 0.
    const double angle = std::acos(std::min(d, 1.0));
    double w0 = 1.0 - u, w1 = u;
    if (angle >= 1e-4) {
        const double sin_angle = std::sin(angle);
        w0 = std::sin((1.0 - u) * angle) / sin_angle;
        w1 = std::sin(u * angle) / sin_angle;
    }
    double r[4];
    for (int i = 0; i < 4; ++i) r[i] = w0 * q0[i] + w1 * q1[i];
    normalize_quaternion(r);
    for (int i = 0; i < 4; ++i) out[i] = float(r[i]);
}

}  // namespace

void sample_animation(const AnimationSampler& s, AnimationPath path, float t, float* out) {
    const size_t n = s.times.size();
    const size_t c = size_t(s.components);
    const auto copy_key = [&](size_t k) { std::copy_n(key_value(s, k), c, out); };

    // Outside the keys the output is clamped to the nearest end (section 3.11); NaN fails the
    // comparison and takes the first key.
    if (n == 1 || !(t > s.times.front())) return copy_key(0);
    if (t >= s.times.back()) return copy_key(n - 1);

    // The interval [t_k, t_k+1) holding t: the first key after t, minus one. Clamped so that even
    // unsorted times keep k and k + 1 inside the keys.
    const auto after = std::upper_bound(s.times.begin(), s.times.end(), t);
    const size_t k = size_t(std::clamp<std::ptrdiff_t>(after - s.times.begin(), 1, std::ptrdiff_t(n - 1))) - 1;
    // A requested time that is a key time takes that key's value as-is (Appendix C, "Overview").
    if (t == s.times[k] || s.interpolation == Interpolation::Step) return copy_key(k);

    const double td = double(s.times[k + 1]) - double(s.times[k]);
    const double u = td > 0.0 ? std::clamp((double(t) - double(s.times[k])) / td, 0.0, 1.0) : 0.0;
    const bool rotation = path == AnimationPath::Rotation && c == 4;

    if (s.interpolation == Interpolation::Linear) {
        const float* v0 = key_value(s, k);
        const float* v1 = key_value(s, k + 1);
        if (rotation) return slerp(v0, v1, u, out);
        for (size_t i = 0; i < c; ++i) out[i] = float((1.0 - u) * v0[i] + u * v1[i]);
        return;
    }

    // Cubic Hermite spline between v_k and v_k+1 with the out-tangent b_k of key k and the
    // in-tangent a_k+1 of key k + 1, both scaled by the interval's duration td.
    const double u2 = u * u, u3 = u2 * u;
    const double h_v0 = 2.0 * u3 - 3.0 * u2 + 1.0;
    const double h_b0 = (u3 - 2.0 * u2 + u) * td;
    const double h_v1 = -2.0 * u3 + 3.0 * u2;
    const double h_a1 = (u3 - u2) * td;
    const float* v0 = element(s, k, 1);
    const float* b0 = element(s, k, 2);
    const float* a1 = element(s, k + 1, 0);
    const float* v1 = element(s, k + 1, 1);
    if (rotation) {
        // The spline leaves the unit sphere: normalise before use (Appendix C, "Cubic Spline").
        double q[4];
        for (int i = 0; i < 4; ++i) q[i] = h_v0 * v0[i] + h_b0 * b0[i] + h_v1 * v1[i] + h_a1 * a1[i];
        normalize_quaternion(q);
        for (int i = 0; i < 4; ++i) out[i] = float(q[i]);
        return;
    }
    for (size_t i = 0; i < c; ++i) out[i] = float(h_v0 * v0[i] + h_b0 * b0[i] + h_v1 * v1[i] + h_a1 * a1[i]);
}

void validate_animation_sampler(const AnimationSampler& s, const std::string& where) {
    const auto fail = [&](const std::string& problem) {
        throw Error(where.empty() ? problem : where + ": " + problem);
    };
    if (s.components < 1) fail(fmt::format("{} components an element; a sampler needs at least 1", s.components));
    if (s.times.empty()) fail("the sampler has no keyframes (its input times are empty)");

    // Times: finite and strictly increasing, so every interval has a positive duration.
    for (size_t i = 0; i < s.times.size(); ++i)
        if (!std::isfinite(s.times[i])) fail(fmt::format("time {} is not finite ({})", i, s.times[i]));
    for (size_t i = 1; i < s.times.size(); ++i)
        if (!(s.times[i] > s.times[i - 1]))
            fail(fmt::format("times must be strictly increasing, but time {} ({}) is not after time {} ({})", i,
                             s.times[i], i - 1, s.times[i - 1]));

    // Values: one element a key, three for CUBICSPLINE, each `components` floats, all finite.
    const bool cubic = s.interpolation == Interpolation::CubicSpline;
    const size_t per_key = (cubic ? 3 : 1) * size_t(s.components);
    const size_t expected = s.times.size() * per_key;
    if (s.values.size() != expected) {
        if (cubic)
            fail(fmt::format("{} values for {} keys of {} components, expected {}: CUBICSPLINE needs 3 values a key "
                             "(in-tangent, value, out-tangent)",
                             s.values.size(), s.times.size(), s.components, expected));
        fail(fmt::format("{} values for {} keys of {} components, expected {}", s.values.size(), s.times.size(),
                         s.components, expected));
    }
    for (size_t i = 0; i < s.values.size(); ++i)
        if (!std::isfinite(s.values[i]))
            fail(fmt::format("value {} (key {}) is not finite ({})", i, i / per_key, s.values[i]));
}

}  // namespace whitted
