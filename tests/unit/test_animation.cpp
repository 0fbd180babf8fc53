// Keyframe samplers (src/scene/animation.h) against values worked out by hand from glTF 2.0
// section 3.11 and Appendix C: STEP, LINEAR (slerp for rotations), CUBICSPLINE on unequal key
// intervals, clamping, NaN and huge times, and every validation error.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "core/error.h"
#include "scene/animation.h"

namespace whitted {
namespace {

constexpr double kPi = 3.14159265358979323846;
const std::string kWhere = "scene.gltf: /animations/0/samplers/1";

double radians(double degrees) { return degrees * kPi / 180.0; }

/// The sampler's output at `t` as a vector of its components.
std::vector<float> sample(const AnimationSampler& s, AnimationPath path, float t) {
    std::vector<float> out(size_t(s.components), -12345.f);
    sample_animation(s, path, t, out.data());
    return out;
}

void expect_values(const std::vector<float>& got, const std::vector<float>& want, float tolerance, const char* what) {
    ASSERT_EQ(got.size(), want.size()) << what;
    for (size_t i = 0; i < want.size(); ++i) EXPECT_NEAR(got[i], want[i], tolerance) << what << ", component " << i;
}

/// Rotation angle in degrees of a quaternion (x, y, z, w) about +Z.
double angle_about_z(const std::vector<float>& q) { return 2.0 * std::atan2(double(q[2]), double(q[3])) * 180.0 / kPi; }

double length4(const std::vector<float>& q) {
    return std::sqrt(double(q[0]) * q[0] + double(q[1]) * q[1] + double(q[2]) * q[2] + double(q[3]) * q[3]);
}

/// validate_animation_sampler must throw one line that starts with kWhere and names `problem`.
void expect_invalid(const AnimationSampler& s, const std::string& problem) {
    try {
        validate_animation_sampler(s, kWhere);
        ADD_FAILURE() << "no error; expected one about: " << problem;
    } catch (const Error& e) {
        const std::string message = e.what();
        EXPECT_EQ(message.rfind(kWhere, 0), 0u) << message;
        EXPECT_NE(message.find(problem), std::string::npos) << message;
        EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
}

// ---- STEP -----------------------------------------------------------------------------------

TEST(AnimationSampling, StepHoldsTheKeyAtOrBefore) {
    // Keys at 1, 2, 4 s with x = 10, 20, 40.
    const AnimationSampler s{{1.f, 2.f, 4.f}, {10, 1, 2, 20, 1, 2, 40, 1, 2}, Interpolation::Step, 3};
    expect_values(sample(s, AnimationPath::Translation, 0.5f), {10, 1, 2}, 0.f, "before the first key");
    expect_values(sample(s, AnimationPath::Translation, 1.f), {10, 1, 2}, 0.f, "at the first key");
    expect_values(sample(s, AnimationPath::Translation, 1.5f), {10, 1, 2}, 0.f, "between keys 0 and 1");
    expect_values(sample(s, AnimationPath::Translation, 2.f), {20, 1, 2}, 0.f, "at key 1");
    expect_values(sample(s, AnimationPath::Translation, 3.99f), {20, 1, 2}, 0.f, "just before key 2");
    expect_values(sample(s, AnimationPath::Translation, 4.f), {40, 1, 2}, 0.f, "at the last key");
    expect_values(sample(s, AnimationPath::Translation, 5.f), {40, 1, 2}, 0.f, "after the last key");
}

// ---- LINEAR ---------------------------------------------------------------------------------

TEST(AnimationSampling, LinearTranslationMidpointAndClamping) {
    // (0, 0, 0) at 0 s to (2, 4, -6) at 2 s; a third key at 4 s back to (0, 0, 0).
    const AnimationSampler s{{0.f, 2.f, 4.f}, {0, 0, 0, 2, 4, -6, 0, 0, 0}, Interpolation::Linear, 3};
    expect_values(sample(s, AnimationPath::Translation, 1.f), {1, 2, -3}, 1e-6f, "midpoint of the first interval");
    // t = 2.5: u = 0.25 into the second interval, 0.75 * (2, 4, -6) = (1.5, 3, -4.5).
    expect_values(sample(s, AnimationPath::Translation, 2.5f), {1.5f, 3.f, -4.5f}, 1e-6f, "second interval");
    expect_values(sample(s, AnimationPath::Translation, 2.f), {2, 4, -6}, 0.f, "at the middle key");
    expect_values(sample(s, AnimationPath::Translation, -1.f), {0, 0, 0}, 0.f, "clamped before the first key");
    expect_values(sample(s, AnimationPath::Translation, 9.f), {0, 0, 0}, 0.f, "clamped after the last key");
    // Scale interpolates the same way.
    const AnimationSampler scale{{0.f, 1.f}, {1, 1, 1, 3, 2, 1}, Interpolation::Linear, 3};
    expect_values(sample(scale, AnimationPath::Scale, 0.5f), {2.f, 1.5f, 1.f}, 1e-6f, "scale midpoint");
}

TEST(AnimationSampling, LinearRotationIsSlerpNotNlerp) {
    // Identity to 170 degrees about Z: q1 = (0, 0, sin 85, cos 85) = (0, 0, 0.9961947, 0.0871557).
    // The quaternions are 85 degrees apart, so slerp at u = 0.25 is 21.25 degrees along the arc:
    // (0, 0, sin 21.25, cos 21.25) = (0, 0, 0.3624380, 0.9320079), a rotation of 42.5 degrees.
    const double h = radians(85.0);
    const AnimationSampler s{{0.f, 1.f}, {0, 0, 0, 1, 0, 0, float(std::sin(h)), float(std::cos(h))},
                             Interpolation::Linear, 4};
    const std::vector<float> q = sample(s, AnimationPath::Rotation, 0.25f);
    expect_values(q, {0.f, 0.f, 0.3624380f, 0.9320079f}, 2e-6f, "slerp at u = 0.25");
    EXPECT_NEAR(angle_about_z(q), 42.5, 1e-4);
    EXPECT_NEAR(length4(q), 1.0, 1e-6);

    // Normalised lerp would give 0.75 q0 + 0.25 q1 = (0, 0, 0.2490487, 0.7717889), whose angle is
    // 2 atan2(0.2490487, 0.7717889) = 2 * 17.8844 = 35.7688 degrees: 6.7 degrees short.
    const double nlerp_angle = 2.0 * std::atan2(0.25 * std::sin(h), 0.75 + 0.25 * std::cos(h)) * 180.0 / kPi;
    EXPECT_NEAR(nlerp_angle, 35.7688, 1e-3);
    EXPECT_GT(std::fabs(angle_about_z(q) - nlerp_angle), 6.0);
}

TEST(AnimationSampling, LinearRotationTakesTheShorterArc) {
    // q1 = -(0, 0, sin 45, cos 45) is +90 degrees about Z written with the opposite sign; the dot
    // with the identity is -0.7071. The short way negates q1 and ends at 45 degrees about Z at
    // u = 0.5: (0, 0, sin 22.5, cos 22.5) = (0, 0, 0.3826834, 0.9238795). The long way (135
    // quaternion degrees) would give (0, 0, -sin 67.5, cos 67.5), a rotation of -135 degrees.
    const float c = float(std::sqrt(0.5));
    const AnimationSampler s{{0.f, 2.f}, {0, 0, 0, 1, 0, 0, -c, -c}, Interpolation::Linear, 4};
    const std::vector<float> q = sample(s, AnimationPath::Rotation, 1.f);
    expect_values(q, {0.f, 0.f, 0.3826834f, 0.9238795f}, 2e-6f, "shorter arc at u = 0.5");
    EXPECT_NEAR(angle_about_z(q), 45.0, 1e-4);
}

TEST(AnimationSampling, LinearRotationNormalisesTheKeysFirst) {
    // The second key is 2 * (0, 0, sin 45, cos 45); slerp of the unit keys at u = 0.5 is
    // (0, 0, sin 22.5, cos 22.5) = (0, 0, 0.3826834, 0.9238795).
    const float c2 = 2.f * float(std::sqrt(0.5));
    const AnimationSampler s{{0.f, 1.f}, {0, 0, 0, 1, 0, 0, c2, c2}, Interpolation::Linear, 4};
    expect_values(sample(s, AnimationPath::Rotation, 0.5f), {0.f, 0.f, 0.3826834f, 0.9238795f}, 2e-6f,
                  "non-unit key");
    // Nearly equal keys (rotations 0.004 degrees apart, quaternions 3.5e-5 rad) take the
    // normalised-lerp path: halfway is a rotation of 0.002 degrees, unit length.
    const double e = radians(0.002);
    const AnimationSampler close_keys{{0.f, 1.f}, {0, 0, 0, 1, 0, 0, float(std::sin(e)), float(std::cos(e))},
                                Interpolation::Linear, 4};
    const std::vector<float> q = sample(close_keys, AnimationPath::Rotation, 0.5f);
    EXPECT_NEAR(length4(q), 1.0, 1e-6);
    EXPECT_NEAR(angle_about_z(q), 0.002, 1e-5);
}

// ---- CUBICSPLINE ----------------------------------------------------------------------------

TEST(AnimationSampling, CubicSplineUsesEachIntervalsDuration) {
    // Keys at 0, 1 and 3 s (durations 1 and 2), each [in-tangent a, value v, out-tangent b]:
    //   key 0: a = (0, 0, 0)   v = (0, 2, 0)   b = (1, 0, 0)
    //   key 1: a = (2, 0, 0)   v = (1, 2, -1)  b = (3, 0, 0)
    //   key 2: a = (-1, 0, 0)  v = (5, 2, 3)   b = (0, 0, 0)
    const AnimationSampler s{{0.f, 1.f, 3.f},
                             {0, 0, 0, 0, 2, 0, 1, 0, 0,  //
                              2, 0, 0, 1, 2, -1, 3, 0, 0,  //
                              -1, 0, 0, 5, 2, 3, 0, 0, 0},
                             Interpolation::CubicSpline, 3};
    // t = 2: second interval, td = 2, u = 0.5: h00 = 0.5, h10 = 0.125, h01 = 0.5, h11 = -0.125.
    //   x = 0.5 * 1 + 0.125 * 2 * 3 + 0.5 * 5 + (-0.125) * 2 * (-1) = 0.5 + 0.75 + 2.5 + 0.25 = 4
    //   (with td taken as 1 it would be 0.5 + 0.375 + 2.5 + 0.125 = 3.5)
    //   y = (0.5 + 0.5) * 2 = 2;  z = 0.5 * (-1) + 0.5 * 3 = 1
    expect_values(sample(s, AnimationPath::Translation, 2.f), {4.f, 2.f, 1.f}, 1e-5f, "t = 2, u = 0.5");
    // t = 1.5: u = 0.25: h00 = 0.84375, h10 = 0.140625, h01 = 0.15625, h11 = -0.046875.
    //   x = 0.84375 + 0.140625 * 2 * 3 + 0.15625 * 5 + 0.046875 * 2 = 0.84375 + 0.84375 + 0.78125 + 0.09375
    //     = 2.5625;  z = -0.84375 + 0.15625 * 3 = -0.375
    expect_values(sample(s, AnimationPath::Translation, 1.5f), {2.5625f, 2.f, -0.375f}, 1e-5f, "t = 1.5, u = 0.25");
    // t = 0.5: first interval, td = 1, u = 0.5: x = 0.125 * 1 + 0.5 * 1 - 0.125 * 2 = 0.375; z = -0.5.
    expect_values(sample(s, AnimationPath::Translation, 0.5f), {0.375f, 2.f, -0.5f}, 1e-5f, "t = 0.5");
    // At and beyond the keys: the values, never the tangents.
    expect_values(sample(s, AnimationPath::Translation, 1.f), {1, 2, -1}, 0.f, "at key 1");
    expect_values(sample(s, AnimationPath::Translation, 3.f), {5, 2, 3}, 0.f, "at the last key");
    expect_values(sample(s, AnimationPath::Translation, 10.f), {5, 2, 3}, 0.f, "after the last key");
    expect_values(sample(s, AnimationPath::Translation, -2.f), {0, 2, 0}, 0.f, "before the first key");
}

TEST(AnimationSampling, CubicSplineRotationIsUnitLength) {
    // Identity to 90 degrees about Z with zero tangents: at u = 0.5 the spline is
    // 0.5 q0 + 0.5 q1 = (0, 0, 0.3535534, 0.8535534), length 0.9238795; normalised it is
    // (0, 0, sin 22.5, cos 22.5) = (0, 0, 0.3826834, 0.9238795).
    const float c = float(std::sqrt(0.5));
    const AnimationSampler flat{{0.f, 1.f}, {0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0,  //
                                             0, 0, 0, 0, 0, 0, c, c, 0, 0, 0, 0},
                                Interpolation::CubicSpline, 4};
    expect_values(sample(flat, AnimationPath::Rotation, 0.5f), {0.f, 0.f, 0.3826834f, 0.9238795f}, 2e-6f,
                  "zero tangents");

    // Non-zero tangents b0 = (1, 0.5, -0.5, 0.2), a1 = (0.3, -0.2, 0.5, 0.1), td = 1, u = 0.5:
    // 0.5 q0 + 0.125 b0 + 0.5 q1 - 0.125 a1 = (0.0875, 0.0875, 0.2285534, 0.8660534), length
    // 0.9042111, so the sample is (0.0967694, 0.0967694, 0.2527655, 0.9578000).
    const AnimationSampler s{{0.f, 1.f}, {0, 0, 0, 0, 0, 0, 0, 1, 1.f, 0.5f, -0.5f, 0.2f,  //
                                          0.3f, -0.2f, 0.5f, 0.1f, 0, 0, c, c, 0, 0, 0, 0},
                             Interpolation::CubicSpline, 4};
    expect_values(sample(s, AnimationPath::Rotation, 0.5f), {0.0967694f, 0.0967694f, 0.2527655f, 0.9578000f}, 2e-6f,
                  "non-zero tangents");
    for (int i = 1; i < 20; ++i) EXPECT_NEAR(length4(sample(s, AnimationPath::Rotation, float(i) / 20.f)), 1.0, 1e-6) << i;
    // As a translation-like vector (no normalisation) the same data keeps the spline's length.
    const std::vector<float> raw = sample(s, AnimationPath::Weights, 0.5f);
    expect_values(raw, {0.0875f, 0.0875f, 0.2285534f, 0.8660534f}, 2e-6f, "same data, not a rotation");
}

// ---- weights, single keys, odd times --------------------------------------------------------

TEST(AnimationSampling, WeightsWithTwoTargets) {
    // (0, 1) at 0 s to (1, 0.5) at 2 s; t = 0.5 is u = 0.25: (0.25, 1 - 0.25 * 0.5) = (0.25, 0.875).
    const AnimationSampler s{{0.f, 2.f}, {0, 1, 1, 0.5f}, Interpolation::Linear, 2};
    expect_values(sample(s, AnimationPath::Weights, 0.5f), {0.25f, 0.875f}, 1e-6f, "linear weights");
    // CUBICSPLINE weights are grouped per key a1 a2 v1 v2 b1 b2 (section 3.11). The unused first
    // in-tangent and last out-tangent are 9s, so a misread layout shows; u = 0.5 with zero
    // tangents gives 0.5 (0, 1) + 0.5 (1, 0) = (0.5, 0.5).
    const AnimationSampler c{{0.f, 1.f}, {9, 9, 0, 1, 0, 0, 0, 0, 1, 0, 9, 9}, Interpolation::CubicSpline, 2};
    expect_values(sample(c, AnimationPath::Weights, 0.5f), {0.5f, 0.5f}, 1e-6f, "cubic weights");
    expect_values(sample(c, AnimationPath::Weights, 0.f), {0, 1}, 0.f, "cubic weights at key 0");
    expect_values(sample(c, AnimationPath::Weights, 1.f), {1, 0}, 0.f, "cubic weights at key 1");
}

TEST(AnimationSampling, SingleKeyGivesItsValueAtAnyTime) {
    const AnimationSampler linear{{0.5f}, {1, 2, 3}, Interpolation::Linear, 3};
    const AnimationSampler step{{0.5f}, {1, 2, 3}, Interpolation::Step, 3};
    const AnimationSampler cubic{{0.5f}, {9, 9, 9, 1, 2, 3, 8, 8, 8}, Interpolation::CubicSpline, 3};
    for (float t : {-5.f, 0.f, 0.5f, 0.75f, 7.f}) {
        expect_values(sample(linear, AnimationPath::Translation, t), {1, 2, 3}, 0.f, "linear");
        expect_values(sample(step, AnimationPath::Translation, t), {1, 2, 3}, 0.f, "step");
        expect_values(sample(cubic, AnimationPath::Translation, t), {1, 2, 3}, 0.f, "cubic");
    }
}

TEST(AnimationSampling, NanAndHugeTimesStayInsideTheKeys) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    const float big = std::numeric_limits<float>::max();
    const float c = float(std::sqrt(0.5));
    // Identity at 1 s, 90 degrees about Z at 2 s, 180 degrees about Z at 4 s.
    const std::vector<float> first{0, 0, 0, 1}, last{0, 0, 1, 0};
    for (Interpolation mode : {Interpolation::Step, Interpolation::Linear, Interpolation::CubicSpline}) {
        AnimationSampler s{{1.f, 2.f, 4.f}, {0, 0, 0, 1, 0, 0, c, c, 0, 0, 1, 0}, mode, 4};
        if (mode == Interpolation::CubicSpline)  // zero tangents around each value
            s.values = {0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, c, c,
                        0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0};
        for (AnimationPath path : {AnimationPath::Rotation, AnimationPath::Weights}) {
            expect_values(sample(s, path, nan), first, 0.f, "NaN is the first key");
            expect_values(sample(s, path, -inf), first, 0.f, "-inf");
            expect_values(sample(s, path, -big), first, 0.f, "-max");
            expect_values(sample(s, path, -1e30f), first, 0.f, "-1e30");
            expect_values(sample(s, path, 1e30f), last, 0.f, "1e30");
            expect_values(sample(s, path, big), last, 0.f, "max");
            expect_values(sample(s, path, inf), last, 0.f, "+inf");
            // One float step before the last key is still inside the last interval.
            for (float v : sample(s, path, std::nextafter(4.f, 0.f))) EXPECT_TRUE(std::isfinite(v));
        }
    }
    // Keys at -3e38 and 3e38 s: their 6e38 s interval overflows float but not the sampler;
    // t = 0 is u = 0.5, halfway from 0 to 10.
    const AnimationSampler wide{{-3e38f, 3e38f}, {0, 10}, Interpolation::Linear, 1};
    expect_values(sample(wide, AnimationPath::Weights, 0.f), {5.f}, 1e-5f, "huge key times");
    validate_animation_sampler(wide, kWhere);
}

// ---- validation -----------------------------------------------------------------------------

TEST(AnimationValidation, WellFormedSamplersPass) {
    EXPECT_NO_THROW(validate_animation_sampler({{0.f, 1.f}, {0, 0, 0, 1, 2, 3}, Interpolation::Linear, 3}, kWhere));
    EXPECT_NO_THROW(validate_animation_sampler({{0.f}, {1}, Interpolation::Step, 1}, kWhere));
    EXPECT_NO_THROW(validate_animation_sampler(
        {{0.f, 1.f}, std::vector<float>(2 * 3 * 4, 0.5f), Interpolation::CubicSpline, 4}, kWhere));
}

TEST(AnimationValidation, EmptyTimes) {
    expect_invalid({{}, {}, Interpolation::Linear, 3}, "no keyframes");
}

TEST(AnimationValidation, TimesNotStrictlyIncreasing) {
    expect_invalid({{0.f, 1.f, 1.f}, std::vector<float>(3, 0.f), Interpolation::Linear, 1},
                   "times must be strictly increasing, but time 2 (1) is not after time 1 (1)");
    expect_invalid({{0.f, 2.f, 1.f}, std::vector<float>(3, 0.f), Interpolation::Step, 1},
                   "times must be strictly increasing, but time 2 (1) is not after time 1 (2)");
}

TEST(AnimationValidation, NonFiniteTime) {
    expect_invalid({{0.f, std::numeric_limits<float>::quiet_NaN(), 2.f}, std::vector<float>(3, 0.f),
                    Interpolation::Linear, 1},
                   "time 1 is not finite");
    expect_invalid({{0.f, std::numeric_limits<float>::infinity()}, std::vector<float>(2, 0.f), Interpolation::Linear, 1},
                   "time 1 is not finite (inf)");
}

TEST(AnimationValidation, WrongValueCount) {
    expect_invalid({{0.f, 1.f}, std::vector<float>(5, 0.f), Interpolation::Linear, 3},
                   "5 values for 2 keys of 3 components, expected 6");
}

TEST(AnimationValidation, CubicSplineNeedsThreeValuesAKey) {
    // One element a key, as a LINEAR sampler would have: 6 of 2 * 3 * 3 = 18 floats.
    expect_invalid({{0.f, 1.f}, std::vector<float>(6, 0.f), Interpolation::CubicSpline, 3},
                   "CUBICSPLINE needs 3 values a key (in-tangent, value, out-tangent)");
    expect_invalid({{0.f, 1.f}, std::vector<float>(6, 0.f), Interpolation::CubicSpline, 3}, "expected 18");
}

TEST(AnimationValidation, ComponentsBelowOne) {
    expect_invalid({{0.f}, {}, Interpolation::Linear, 0}, "at least 1");
}

TEST(AnimationValidation, NonFiniteValue) {
    expect_invalid({{0.f, 1.f}, {0, 0, 0, 1, std::numeric_limits<float>::quiet_NaN(), 3}, Interpolation::Linear, 3},
                   "value 4 (key 1) is not finite");
}

}  // namespace
}  // namespace whitted
