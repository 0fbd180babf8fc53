// Keyframe animation samplers as plain data, and the functions that read them: glTF 2.0
// section 3.11 "Animations" (clamping outside the keys, output layouts) and Appendix C
// "Animation Sampler Interpolation Modes" (STEP, LINEAR with slerp for rotations, CUBICSPLINE).
#pragma once

#include <string>
#include <vector>

namespace whitted {

/// How values between two keys are computed (glTF `animation.sampler.interpolation`).
enum class Interpolation { Step, Linear, CubicSpline };

/// The node property a sampler drives (glTF `animation.channel.target.path`).
enum class AnimationPath { Translation, Rotation, Scale, Weights };

/// One glTF animation sampler: key times (input) and the values at them (output), decoded to float.
struct AnimationSampler {
    std::vector<float> times;                       ///< key times in seconds, strictly increasing
    std::vector<float> values;                      ///< `components` floats per element; one element a key, or for
                                                    ///< CubicSpline three a key: in-tangent, value, out-tangent
    Interpolation interpolation = Interpolation::Linear;  ///< glTF's default is LINEAR
    int components = 1;                             ///< floats per element: 3 translation/scale, 4 rotation
                                                    ///< quaternion (x, y, z, w), morph target count for weights
};

/// Writes the sampler's `s.components` floats at time `t` (seconds) to `out`. `s` must pass
/// validate_animation_sampler. Times before the first key (and NaN) give the first value, after
/// the last key the last value; at a key time that key's value as stored. Interpolated rotations
/// (4 components) are unit quaternions: slerp along the shorter arc for LINEAR, the normalised
/// spline for CUBICSPLINE, the identity (0, 0, 0, 1) where the spline passes through zero.
void sample_animation(const AnimationSampler& s, AnimationPath path, float t, float* out);

/// Throws whitted::Error, one line starting with `where`, unless `s` has at least one key, finite
/// strictly increasing times, components >= 1, and times.size() * components finite values
/// (three times as many for CUBICSPLINE).
void validate_animation_sampler(const AnimationSampler& s, const std::string& where);

}  // namespace whitted
