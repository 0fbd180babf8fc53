// The generated skinned tube of `whitted bench anim` (generated_skin.h): geometry, skin and
// animation laid out in one binary buffer, then the glTF JSON and the GLB container.
#include "benchmarks/generated_skin.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "benchmarks/glb_writer.h"
#include "core/error.h"

namespace whitted::app {

namespace {

constexpr double kRadius = 0.5;
constexpr double kHeight = 8.0;
constexpr double kAmplitude = 0.25;  ///< radians of each joint's swing
constexpr double kPhaseStep = 0.7;   ///< radians of phase from one joint to the next
constexpr double kAxisStep = 0.5;    ///< radians the swing axis turns about +Y from one joint to the next

/// Uniform cubic B-spline kernel: weights at integer offsets of any point sum to 1.
double bspline(double t) {
    t = std::abs(t);
    if (t < 1.0) return (4.0 - 6.0 * t * t + 3.0 * t * t * t) / 6.0;
    if (t < 2.0) return (2.0 - t) * (2.0 - t) * (2.0 - t) / 6.0;
    return 0.0;
}


}  // namespace

GeneratedSkin write_generated_skin(const std::filesystem::path& path, const GeneratedSkinSpec& spec) {
    if (spec.joints < 4 || spec.joints > 1000)
        throw Error(fmt::format("generated skin: {} joints (expected 4 to 1000)", spec.joints));
    if (spec.keys < 2) throw Error(fmt::format("generated skin: {} keys (expected 2 or more)", spec.keys));
    if (!(spec.duration > 0.0 && std::isfinite(spec.duration)))
        throw Error(fmt::format("generated skin: duration {} s (expected a positive number)", spec.duration));
    if (spec.triangles > size_t(200) << 20)
        throw Error(fmt::format("generated skin: {} triangles (at most {})", spec.triangles, size_t(200) << 20));

    // The grid: about twice as many rings as segments (2 x s x 2s = 4 s^2 triangles).
    GeneratedSkin out;
    out.segments = std::max(6, int(std::lround(std::sqrt(double(spec.triangles) / 4.0))));
    out.rings = 1 + std::max(2, int(std::lround(double(spec.triangles) / (2.0 * out.segments))));
    const size_t seg = size_t(out.segments), rings = size_t(out.rings);
    out.vertices = seg * rings;
    out.triangles = 2 * seg * (rings - 1);

    // Vertices: ring i at height i / (rings - 1) x kHeight, segment j at angle 2 pi j / segments.
    const int joints = spec.joints;
    const double bone = kHeight / joints;
    std::vector<float> positions(3 * out.vertices), normals(3 * out.vertices), weights(4 * out.vertices);
    std::vector<uint16_t> joint_ids(4 * out.vertices);
    float lo[3] = {float(-kRadius), 0.f, float(-kRadius)}, hi[3] = {float(kRadius), float(kHeight), float(kRadius)};
    for (size_t i = 0; i < rings; ++i) {
        const double y = kHeight * double(i) / double(rings - 1);
        // The 4 joints nearest the height, by the B-spline over bone centres (bone k at (k + 0.5) x bone).
        const double s = y / bone - 0.5;
        const int first = std::clamp(int(std::floor(s)) - 1, 0, joints - 4);
        double w[4], sum = 0.0;
        for (int k = 0; k < 4; ++k) sum += (w[k] = bspline(s - double(first + k)));
        for (size_t j = 0; j < seg; ++j) {
            const double a = 2.0 * std::numbers::pi * double(j) / double(seg);
            const size_t v = i * seg + j;
            positions[3 * v + 0] = float(kRadius * std::cos(a));
            positions[3 * v + 1] = float(y);
            positions[3 * v + 2] = float(kRadius * std::sin(a));
            normals[3 * v + 0] = float(std::cos(a));
            normals[3 * v + 1] = 0.f;
            normals[3 * v + 2] = float(std::sin(a));
            for (int k = 0; k < 4; ++k) {
                joint_ids[4 * v + size_t(k)] = uint16_t(first + k);
                weights[4 * v + size_t(k)] = float(w[k] / sum);
            }
        }
    }
    for (int c : {0, 2})
        for (size_t v = 0; v < out.vertices; ++v) {
            lo[c] = std::min(lo[c], positions[3 * v + size_t(c)]);
            hi[c] = std::max(hi[c], positions[3 * v + size_t(c)]);
        }
    // Triangles, counter-clockwise seen from outside.
    std::vector<uint32_t> indices;
    indices.reserve(3 * out.triangles);
    for (size_t i = 0; i + 1 < rings; ++i)
        for (size_t j = 0; j < seg; ++j) {
            const uint32_t a = uint32_t(i * seg + j), b = uint32_t(i * seg + (j + 1) % seg);
            const uint32_t c = uint32_t(a + seg), d = uint32_t(b + seg);
            indices.insert(indices.end(), {a, c, b, b, c, d});
        }
    // The skin: joint j bound at height j x bone, so its inverse bind matrix moves down by that.
    std::vector<float> inverse_bind(16 * size_t(joints), 0.f);
    for (int j = 0; j < joints; ++j) {
        float* m = &inverse_bind[16 * size_t(j)];
        m[0] = m[5] = m[10] = m[15] = 1.f;
        m[13] = float(-bone * j);  // column-major: translation in elements 12..14
    }
    // The animation: one rotation channel per joint, keys evenly spaced.
    std::vector<float> times(size_t(spec.keys));
    for (int k = 0; k < spec.keys; ++k) times[size_t(k)] = float(spec.duration * k / (spec.keys - 1));

    GlbLayout l;
    const std::string pos_bounds = fmt::format(", \"min\": [{}, {}, {}], \"max\": [{}, {}, {}]", lo[0], lo[1], lo[2],
                                               hi[0], hi[1], hi[2]);
    const int a_pos = l.add(positions, 5126, "VEC3", out.vertices, 34962, pos_bounds);
    const int a_nrm = l.add(normals, 5126, "VEC3", out.vertices, 34962);
    const int a_jnt = l.add(joint_ids, 5123, "VEC4", out.vertices, 34962);
    const int a_wgt = l.add(weights, 5126, "VEC4", out.vertices, 34962);
    const int a_idx = l.add(indices, 5125, "SCALAR", indices.size(), 34963);
    const int a_ibm = l.add(inverse_bind, 5126, "MAT4", size_t(joints), 0);
    const int a_time = l.add(times, 5126, "SCALAR", times.size(), 0,
                             fmt::format(", \"min\": [{}], \"max\": [{}]", times.front(), times.back()));
    std::vector<std::string> samplers, channels;
    for (int j = 0; j < joints; ++j) {
        const double phi = kAxisStep * j;
        std::vector<float> q(4 * size_t(spec.keys));
        for (int k = 0; k < spec.keys; ++k) {
            const double angle = kAmplitude * std::sin(2.0 * std::numbers::pi * times[size_t(k)] / spec.duration + kPhaseStep * j);
            const double s = std::sin(0.5 * angle);
            float* e = &q[4 * size_t(k)];
            e[0] = float(std::cos(phi) * s);  // axis (cos phi, 0, sin phi), quaternion (x, y, z, w)
            e[1] = 0.f;
            e[2] = float(std::sin(phi) * s);
            e[3] = float(std::cos(0.5 * angle));
        }
        const int a_rot = l.add(q, 5126, "VEC4", size_t(spec.keys), 0);
        samplers.push_back(fmt::format("{{\"input\": {}, \"output\": {}, \"interpolation\": \"LINEAR\"}}", a_time, a_rot));
        channels.push_back(fmt::format("{{\"sampler\": {}, \"target\": {{\"node\": {}, \"path\": \"rotation\"}}}}", j, j));
    }

    // Nodes: the joint chain 0 .. joints-1 (each the child of the one before), then the mesh node.
    std::vector<std::string> nodes, joint_list;
    for (int j = 0; j < joints; ++j) {
        nodes.push_back(fmt::format("{{\"name\": \"joint{}\", \"translation\": [0, {}, 0]{}}}", j, j ? bone : 0.0,
                                    j + 1 < joints ? fmt::format(", \"children\": [{}]", j + 1) : ""));
        joint_list.push_back(std::to_string(j));
    }
    nodes.push_back("{\"name\": \"tube\", \"mesh\": 0, \"skin\": 0}");
    const std::string json = fmt::format(
        "{{\"asset\": {{\"version\": \"2.0\", \"generator\": \"whitted bench anim (benchmarks/generated_skin.cpp)\"}},\n"
        " \"scene\": 0, \"scenes\": [{{\"nodes\": [0, {}]}}],\n"
        " \"nodes\": [\n  {}],\n"
        " \"meshes\": [{{\"name\": \"tube\", \"primitives\": [{{\"attributes\": {{\"POSITION\": {}, \"NORMAL\": {}, "
        "\"JOINTS_0\": {}, \"WEIGHTS_0\": {}}}, \"indices\": {}, \"material\": 0}}]}}],\n"
        " \"materials\": [{{\"name\": \"clay\", \"doubleSided\": true, \"pbrMetallicRoughness\": "
        "{{\"baseColorFactor\": [0.8, 0.45, 0.3, 1], \"metallicFactor\": 0, \"roughnessFactor\": 0.6}}}}],\n"
        " \"skins\": [{{\"name\": \"chain\", \"joints\": [{}], \"inverseBindMatrices\": {}, \"skeleton\": 0}}],\n"
        " \"animations\": [{{\"name\": \"sway\", \"samplers\": [\n  {}],\n \"channels\": [\n  {}]}}],\n"
        " \"accessors\": [\n  {}],\n"
        " \"bufferViews\": [\n  {}],\n"
        " \"buffers\": [{{\"byteLength\": {}}}]}}\n",
        joints, join(nodes, ",\n  "), a_pos, a_nrm, a_jnt, a_wgt, a_idx, join(joint_list, ", "), a_ibm,
        join(samplers, ",\n  "), join(channels, ",\n  "), join(l.accessors, ",\n  "), join(l.views, ",\n  "),
        l.bin.size());

    const size_t total = write_glb(path, json, l.bin, "generated skin");
    out.bytes = total;
    return out;
}

}  // namespace whitted::app
