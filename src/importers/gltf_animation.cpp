#include "importers/gltf_animation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <numbers>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.h"
#include "importers/gltf_accessor.h"
#include "importers/located_error.h"
#include "importers/scene_loader.h"
#include "scene/animation.h"

namespace whitted {

using namespace gltf;

namespace {

constexpr int kFloat = TINYGLTF_COMPONENT_TYPE_FLOAT;

std::string animation_name(const tinygltf::Model& model, int a) {
    const std::string& n = model.animations[size_t(a)].name;
    return n.empty() ? fmt::format("animation {}", a) : n;
}

/// An animation's duration: the last key time over its samplers (their input accessors' max).
double animation_duration(const tinygltf::Model& model, const tinygltf::Animation& anim) {
    double duration = 0.0;
    for (const tinygltf::AnimationSampler& s : anim.samplers)
        if (s.input >= 0 && size_t(s.input) < model.accessors.size() && !model.accessors[size_t(s.input)].maxValues.empty())
            duration = std::max(duration, model.accessors[size_t(s.input)].maxValues[0]);
    return duration;
}

/// Morph targets of a mesh: the largest count over its primitives (the spec wants them equal).
size_t target_count(const tinygltf::Mesh& mesh) {
    size_t n = 0;
    for (const tinygltf::Primitive& p : mesh.primitives) n = std::max(n, p.targets.size());
    return n;
}

/// A node's translation, rotation and scale (or its fixed matrix), which channels overwrite. Only
/// the parts present (in the file or from a channel) are multiplied in: a node nothing animates
/// composes exactly its stored parts, with no identity factor in between.
struct NodeTrs {
    std::array<double, 3> t{0, 0, 0};
    std::array<double, 4> r{0, 0, 0, 1};
    std::array<double, 3> s{1, 1, 1};
    bool has_t = false, has_r = false, has_s = false;
    bool has_matrix = false;
    Mat4d matrix;

    Mat4d local() const {
        if (has_matrix) return matrix;
        Mat4d m;
        if (has_t) m = Mat4d::translate({t[0], t[1], t[2]});
        if (has_r) {
            const double n = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2] + r[3] * r[3]);
            if (n > 1e-12) m = m * Mat4d::rotate(r[0] / n, r[1] / n, r[2] / n, r[3] / n);
        }
        if (has_s) m = m * Mat4d::scale({s[0], s[1], s[2]});
        return m;
    }
};

NodeTrs node_trs(const tinygltf::Node& node) {
    NodeTrs n;
    if (node.matrix.size() == 16) {
        n.has_matrix = true;
        for (int c = 0; c < 4; ++c)  // glTF stores column-major
            for (int r = 0; r < 4; ++r) n.matrix(r, c) = node.matrix[size_t(c * 4 + r)];
    }
    n.has_t = node.translation.size() == 3;
    n.has_r = node.rotation.size() == 4;
    n.has_s = node.scale.size() == 3;
    for (size_t i = 0; i < 3 && n.has_t; ++i) n.t[i] = node.translation[i];
    for (size_t i = 0; i < 4 && n.has_r; ++i) n.r[i] = node.rotation[i];
    for (size_t i = 0; i < 3 && n.has_s; ++i) n.s[i] = node.scale[i];
    return n;
}

/// Reads sampler `s` of animation `a` for `path`, checking its accessors against the spec.
class SamplerReader {
public:
    SamplerReader(const tinygltf::Model& model, const std::string& file) : m_model(model), m_file(file) {}

    /// `label` names the animated property in messages (default: the path's name).
    /// `output_type`: the accessor type the values must have when not the path's (a VEC2 texture
    /// offset or scale of KHR_animation_pointer), FLOAT only.
    AnimationSampler read(int a, int s, AnimationPath path, int components, const char* label = nullptr,
                          int output_type = 0) const {
        const std::string ptr = fmt::format("/animations/{}/samplers/{}", a, s);
        const tinygltf::AnimationSampler& g = m_model.animations[size_t(a)].samplers[size_t(s)];
        AnimationSampler out;
        out.components = components;
        if (g.interpolation == "STEP") out.interpolation = Interpolation::Step;
        else if (g.interpolation == "CUBICSPLINE") out.interpolation = Interpolation::CubicSpline;
        else if (g.interpolation.empty() || g.interpolation == "LINEAR") out.interpolation = Interpolation::Linear;
        else fail(ptr + "/interpolation", "unknown interpolation '{}' (LINEAR, STEP or CUBICSPLINE)", g.interpolation);
        const tinygltf::Accessor& in = accessor(g.input, ptr + "/input");
        if (in.type != TINYGLTF_TYPE_SCALAR || in.componentType != kFloat)
            fail(ptr + "/input", "key times must be a SCALAR FLOAT accessor (accessor {})", g.input);
        out.times.resize(in.count);
        for_each_element(accessor_data(m_model, g.input), [&](size_t i, const float* v) { out.times[i] = v[0]; });
        const tinygltf::Accessor& o = accessor(g.output, ptr + "/output");
        const bool normalized_int = o.normalized && o.componentType != kFloat;
        const int expected_type = output_type                       ? output_type
                                  : path == AnimationPath::Weights  ? TINYGLTF_TYPE_SCALAR
                                  : path == AnimationPath::Rotation ? TINYGLTF_TYPE_VEC4
                                                                    : TINYGLTF_TYPE_VEC3;
        const bool int_ok = !output_type && (path == AnimationPath::Rotation || path == AnimationPath::Weights);
        if (o.type != expected_type || !(o.componentType == kFloat || (int_ok && normalized_int)))
            fail(ptr + "/output", "{} values must be a {} FLOAT{} accessor (accessor {} is {} {})",
                 label ? label : path_name(path),
                 type_name(expected_type), int_ok ? " or normalized integer" : "", g.output, type_name(o.type),
                 component_type_name(o.componentType));
        const size_t per = size_t(component_count(o.type));
        out.values.assign(o.count * per, 0.f);
        for_each_element(accessor_data(m_model, g.output), [&](size_t i, const float* v) {
            for (size_t c = 0; c < per; ++c) out.values[i * per + c] = v[c];
        });
        try {
            validate_animation_sampler(out, "");
        } catch (const Error& e) {
            std::string what = e.what();
            if (what.rfind(": ", 0) == 0) what = what.substr(2);
            fail(ptr, "{} ({} keys, output accessor {})", what, out.times.size(), g.output);
        }
        return out;
    }

    static const char* path_name(AnimationPath p) {
        switch (p) {
            case AnimationPath::Translation: return "translation";
            case AnimationPath::Rotation: return "rotation";
            case AnimationPath::Scale: return "scale";
            default: return "weights";
        }
    }

    template <typename... Args>
    [[noreturn]] void fail(const std::string& pointer, fmt::format_string<Args...> f, Args&&... args) const {
        throw Error(file_loc(m_file, pointer), fmt::format(f, std::forward<Args>(args)...));
    }

private:
    const tinygltf::Accessor& accessor(int index, const std::string& ptr) const {
        if (index < 0 || size_t(index) >= m_model.accessors.size())
            fail(ptr, "accessor {} does not exist (the file has {})", index, m_model.accessors.size());
        return m_model.accessors[size_t(index)];
    }

    const tinygltf::Model& m_model;
    const std::string& m_file;
};

/// The default morph weights of node `n`: node.weights, else mesh.weights, else 0 (empty: no targets).
std::vector<float> default_weights(const tinygltf::Model& model, const std::string& file, int n) {
    const tinygltf::Node& node = model.nodes[size_t(n)];
    if (node.mesh < 0) return {};
    const tinygltf::Mesh& mesh = model.meshes[size_t(node.mesh)];
    const size_t targets = target_count(mesh);
    if (targets == 0) return {};
    for (const tinygltf::Primitive& p : mesh.primitives)
        if (p.targets.size() != targets)
            throw Error(file_loc(file, fmt::format("/meshes/{}", node.mesh)),
                        fmt::format("its primitives have different numbers of morph targets ({} and {})",
                                    p.targets.size(), targets));
    auto take = [&](const std::vector<double>& w, const std::string& ptr) {
        if (w.size() != targets)
            throw Error(file_loc(file, ptr), fmt::format("{} weights for {} morph targets", w.size(), targets));
        std::vector<float> out(targets);
        for (size_t i = 0; i < targets; ++i) {
            if (!std::isfinite(w[i])) throw Error(file_loc(file, ptr), fmt::format("weight {} is not finite", i));
            out[i] = float(w[i]);
        }
        return out;
    };
    if (!node.weights.empty()) return take(node.weights, fmt::format("/nodes/{}/weights", n));
    if (!mesh.weights.empty()) return take(mesh.weights, fmt::format("/meshes/{}/weights", node.mesh));
    return std::vector<float>(targets, 0.f);
}

/// A KHR_animation_pointer channel's JSON pointer ("" when it has none).
std::string animation_pointer(const tinygltf::AnimationChannel& ch) {
    const auto ext = ch.target_extensions.find("KHR_animation_pointer");
    if (ext == ch.target_extensions.end() || !ext->second.IsObject() || !ext->second.Has("pointer")) return {};
    const tinygltf::Value& v = ext->second.Get("pointer");
    return v.IsString() ? v.Get<std::string>() : std::string();
}

/// "<prefix>N<suffix>" as N; false when `pointer` has another shape.
bool indexed_pointer(const std::string& pointer, const std::string& prefix, const std::string& suffix, int& index) {
    if (pointer.size() <= prefix.size() + suffix.size() || pointer.rfind(prefix, 0) != 0 ||
        pointer.compare(pointer.size() - suffix.size(), suffix.size(), suffix) != 0)
        return false;
    const std::string n = pointer.substr(prefix.size(), pointer.size() - prefix.size() - suffix.size());
    if (n.empty() || n.size() > 9 || n.find_first_not_of("0123456789") != std::string::npos) return false;
    index = std::stoi(n);
    return true;
}

/// The value at time `t` of a KHR_animation_pointer channel's sampler: `components` floats (a
/// SCALAR or VEC2/VEC3/VEC4 accessor), interpolated component by component; `label` names the property.
std::vector<float> sample_pointer(const tinygltf::Model& model, const SamplerReader& reader, int a,
                                  const tinygltf::AnimationChannel& ch, const std::string& ptr, double t,
                                  int components, const char* label) {
    if (ch.sampler < 0 || size_t(ch.sampler) >= model.animations[size_t(a)].samplers.size())
        reader.fail(ptr + "/sampler", "sampler {} does not exist", ch.sampler);
    const AnimationPath as = components == 1   ? AnimationPath::Weights      // a SCALAR accessor
                             : components == 3 ? AnimationPath::Translation  // VEC3
                                               : AnimationPath::Rotation;    // VEC4
    const AnimationSampler s =
        reader.read(a, ch.sampler, as, components, label, components == 2 ? TINYGLTF_TYPE_VEC2 : 0);
    std::vector<float> v(static_cast<size_t>(components));
    // Not a rotation: no quaternion interpolation for 4 components.
    sample_animation(s, as == AnimationPath::Rotation ? AnimationPath::Translation : as, float(t), v.data());
    return v;
}

/// Applies a KHR_animation_pointer channel to a camera's yfov or a light's color or intensity;
/// false when the pointer is not one of those.
bool apply_object_pointer(const tinygltf::Model& model, const SamplerReader& reader, const std::string& pointer,
                          int a, const tinygltf::AnimationChannel& ch, const std::string& ptr, double t,
                          GltfPose& pose) {
    int index = -1;
    size_t objects = 0;
    int components = 1;
    const char* label = "";
    GltfPose::Collection collection = GltfPose::Collection::Lights;
    const char* property = "";
    if (indexed_pointer(pointer, "/cameras/", "/perspective/yfov", index)) {
        collection = GltfPose::Collection::Cameras, objects = model.cameras.size(), label = "camera yfov",
        property = "perspective/yfov";
    } else if (indexed_pointer(pointer, "/extensions/KHR_lights_punctual/lights/", "/color", index)) {
        objects = model.lights.size(), components = 3, label = "light color", property = "color";
    } else if (indexed_pointer(pointer, "/extensions/KHR_lights_punctual/lights/", "/intensity", index)) {
        objects = model.lights.size(), label = "light intensity", property = "intensity";
    } else {
        return false;
    }
    if (size_t(index) >= objects) reader.fail(ptr + "/target", "{} points at an object that does not exist", pointer);
    std::vector<float> v = sample_pointer(model, reader, a, ch, ptr, t, components, label);
    const bool yfov = collection == GltfPose::Collection::Cameras;
    for (const float x : v)
        if (yfov ? !(x > 0.f && x < float(std::numbers::pi)) : !(x >= 0.f))
            reader.fail(ptr, "{} is {} at {} s ({})", label, x, t,
                        yfov ? "yfov must be in (0, pi)" : "it must not be negative");
    pose.values.push_back({collection, index, property, std::move(v)});
    return true;
}

/// The core material properties KHR_animation_pointer may animate here, with their components and range.
struct MaterialProperty {
    const char* path;
    int components;
    float lo, hi;
};
constexpr MaterialProperty kMaterialProperties[] = {
    {"pbrMetallicRoughness/baseColorFactor", 4, 0.f, 1.f},
    {"pbrMetallicRoughness/metallicFactor", 1, 0.f, 1.f},
    {"pbrMetallicRoughness/roughnessFactor", 1, 0.f, 1.f},
    {"emissiveFactor", 3, 0.f, 1.f},
    {"alphaCutoff", 1, 0.f, 3.4e38f},
    {"normalTexture/scale", 1, -3.4e38f, 3.4e38f},
    {"occlusionTexture/strength", 1, 0.f, 1.f},
    // The material extensions' factors (written into the material's extension object).
    {"extensions/KHR_materials_emissive_strength/emissiveStrength", 1, 0.f, 3.4e38f},
    {"extensions/KHR_materials_transmission/transmissionFactor", 1, 0.f, 1.f},
    {"extensions/KHR_materials_ior/ior", 1, 0.f, 3.4e38f},
    {"extensions/KHR_materials_specular/specularFactor", 1, 0.f, 1.f},
    {"extensions/KHR_materials_specular/specularColorFactor", 3, 0.f, 3.4e38f},
    {"extensions/KHR_materials_volume/thicknessFactor", 1, 0.f, 3.4e38f},
    {"extensions/KHR_materials_volume/attenuationColor", 3, 0.f, 1.f},
    {"extensions/KHR_materials_clearcoat/clearcoatFactor", 1, 0.f, 1.f},
    {"extensions/KHR_materials_clearcoat/clearcoatRoughnessFactor", 1, 0.f, 1.f},
    {"extensions/KHR_materials_sheen/sheenColorFactor", 3, 0.f, 1.f},
    {"extensions/KHR_materials_sheen/sheenRoughnessFactor", 1, 0.f, 1.f},
    {"extensions/KHR_materials_iridescence/iridescenceFactor", 1, 0.f, 1.f},
    {"extensions/KHR_materials_iridescence/iridescenceIor", 1, 1.f, 3.4e38f},
    {"extensions/KHR_materials_iridescence/iridescenceThicknessMinimum", 1, 0.f, 3.4e38f},
    {"extensions/KHR_materials_iridescence/iridescenceThicknessMaximum", 1, 0.f, 3.4e38f},
    {"extensions/KHR_materials_anisotropy/anisotropyStrength", 1, 0.f, 1.f},
    {"extensions/KHR_materials_anisotropy/anisotropyRotation", 1, -3.4e38f, 3.4e38f},
    {"extensions/KHR_materials_dispersion/dispersion", 1, 0.f, 3.4e38f},
    {"extensions/KHR_materials_diffuse_transmission/diffuseTransmissionFactor", 1, 0.f, 1.f},
    {"extensions/KHR_materials_diffuse_transmission/diffuseTransmissionColorFactor", 3, 0.f, 1.f},
};
constexpr const char* kExtensions = "extensions/";

/// The core textureInfo slots of a material, and the KHR_texture_transform properties of each that
/// KHR_animation_pointer may animate (any finite value).
constexpr const char* kTextureSlots[] = {"pbrMetallicRoughness/baseColorTexture",
                                         "pbrMetallicRoughness/metallicRoughnessTexture", "normalTexture",
                                         "occlusionTexture", "emissiveTexture"};
struct TextureTransformProperty {
    const char* path;
    int components;
};
constexpr TextureTransformProperty kTextureTransformProperties[] = {{"offset", 2}, {"rotation", 1}, {"scale", 2}};
constexpr const char* kTextureTransform = "/extensions/KHR_texture_transform/";

/// Applies a KHR_animation_pointer channel to a core material property ("/materials/N/..."): a
/// factor of kMaterialProperties or a KHR_texture_transform property of a core texture slot; false
/// for other pointers.
bool apply_material_pointer(const tinygltf::Model& model, const SamplerReader& reader, const std::string& pointer,
                            int a, const tinygltf::AnimationChannel& ch, const std::string& ptr, double t,
                            GltfPose& pose) {
    for (const char* slot : kTextureSlots)
        for (const TextureTransformProperty& p : kTextureTransformProperties) {
            const std::string property = std::string(slot) + kTextureTransform + p.path;
            int index = -1;
            if (!indexed_pointer(pointer, "/materials/", "/" + property, index)) continue;
            if (size_t(index) >= model.materials.size())
                reader.fail(ptr + "/target", "{} points at a material that does not exist", pointer);
            std::vector<float> v = sample_pointer(model, reader, a, ch, ptr, t, p.components, p.path);
            for (const float x : v)
                if (!std::isfinite(x)) reader.fail(ptr, "texture transform {} is {} at {} s", p.path, x, t);
            pose.values.push_back({GltfPose::Collection::Materials, index, property, std::move(v)});
            return true;
        }
    for (const MaterialProperty& p : kMaterialProperties) {
        int index = -1;
        if (!indexed_pointer(pointer, "/materials/", std::string("/") + p.path, index)) continue;
        if (size_t(index) >= model.materials.size())
            reader.fail(ptr + "/target", "{} points at a material that does not exist", pointer);
        std::vector<float> v = sample_pointer(model, reader, a, ch, ptr, t, p.components, p.path);
        for (float& x : v) x = std::clamp(x, p.lo, p.hi);
        pose.values.push_back({GltfPose::Collection::Materials, index, p.path, std::move(v)});
        return true;
    }
    return false;
}

/// "/nodes/N/translation" (rotation, scale, weights) as a node and a core path; false for others.
bool node_pointer(const std::string& pointer, int& node, std::string& path) {
    for (const char* property : {"translation", "rotation", "scale", "weights"})
        if (indexed_pointer(pointer, "/nodes/", std::string("/") + property, node)) {
            path = property;
            return true;
        }
    return false;
}

}  // namespace

std::vector<int> choose_animations(const tinygltf::Model& model, const std::string& path, const std::string& choice) {
    const int n = int(model.animations.size());
    std::vector<int> out;
    if (choice.empty() || choice == "all") {
        for (int a = 0; a < n; ++a) out.push_back(a);
        return out;
    }
    auto available = [&] {
        if (n == 0) return std::string("the file has no animation");
        std::string s = "the file has:";
        for (int a = 0; a < n; ++a) s += fmt::format(" {} \"{}\"{}", a, animation_name(model, a), a + 1 < n ? "," : "");
        return s;
    };
    for (int a = 0; a < n; ++a)
        if (model.animations[size_t(a)].name == choice) return {a};
    std::stringstream in(choice);
    for (std::string item; std::getline(in, item, ',');) {
        size_t used = 0;
        int index = -1;
        try {
            index = std::stoi(item, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        if (used != item.size() || item.empty() || index < 0 || index >= n)
            throw Error(file_loc(path), fmt::format("--animation {}: no animation '{}' ({})", choice, item, available()));
        if (std::find(out.begin(), out.end(), index) == out.end()) out.push_back(index);
    }
    return out;
}

GltfPose pose_nodes(const tinygltf::Model& model, const std::string& path, const std::vector<int>& animations,
                    double time, bool loop, WarningLog& warnings) {
    check_animation_time(time, "--time");
    const size_t count = model.nodes.size();
    std::vector<NodeTrs> trs(count);
    GltfPose pose;
    pose.weights.resize(count);
    pose.moving.assign(count, 0);
    pose.morphing.assign(count, 0);
    for (size_t n = 0; n < count; ++n) {
        trs[n] = node_trs(model.nodes[n]);
        pose.weights[n] = default_weights(model, path, int(n));
    }
    const SamplerReader reader(model, path);
    for (const int a : animations) {
        const tinygltf::Animation& anim = model.animations[size_t(a)];
        const double duration = animation_duration(model, anim);
        const double t = loop && duration > 0.0 ? std::fmod(time, duration) : time;
        for (size_t c = 0; c < anim.channels.size(); ++c) {
            const tinygltf::AnimationChannel& ch = anim.channels[c];
            const std::string ptr = fmt::format("/animations/{}/channels/{}", a, c);
            int node = ch.target_node;
            std::string path_name = ch.target_path;
            if (ch.target_path == "pointer") {
                // KHR_animation_pointer: the node properties a core channel could target.
                const std::string pointer = animation_pointer(ch);
                if (apply_object_pointer(model, reader, pointer, a, ch, ptr, t, pose)) continue;
                if (apply_material_pointer(model, reader, pointer, a, ch, ptr, t, pose)) continue;
                if (!node_pointer(pointer, node, path_name)) {
                    warnings.add("animation-pointer:" + pointer,
                                 fmt::format("{}: KHR_animation_pointer target {} is not applied (whitted animates "
                                             "node translation, rotation, scale and weights, camera yfov, light "
                                             "color and intensity, core material factors)",
                                             animation_name(model, a), pointer.empty() ? "(none)" : pointer));
                    continue;
                }
            }
            if (node < 0 || size_t(node) >= count)
                reader.fail(ptr + "/target", "node {} does not exist (the file has {})", node, count);
            if (ch.sampler < 0 || size_t(ch.sampler) >= anim.samplers.size())
                reader.fail(ptr + "/sampler", "sampler {} does not exist (the animation has {})", ch.sampler,
                            anim.samplers.size());
            AnimationPath p;
            int components = 3;
            if (path_name == "translation") p = AnimationPath::Translation;
            else if (path_name == "rotation") p = AnimationPath::Rotation, components = 4;
            else if (path_name == "scale") p = AnimationPath::Scale;
            else if (path_name == "weights") {
                p = AnimationPath::Weights;
                components = int(pose.weights[size_t(node)].size());
                if (components == 0)
                    reader.fail(ptr + "/target", "animates the morph weights of node {}, whose mesh has no morph "
                                "targets", node);
            } else {
                reader.fail(ptr + "/target/path", "unknown path '{}' (translation, rotation, scale or weights)",
                            path_name);
            }
            if (p != AnimationPath::Weights && trs[size_t(node)].has_matrix)
                reader.fail(ptr + "/target", "animates node {}, which has a matrix (an animated node must use "
                            "translation, rotation and scale)", node);
            const AnimationSampler s = reader.read(a, ch.sampler, p, components);
            std::vector<float> v(static_cast<size_t>(components));
            sample_animation(s, p, float(t), v.data());
            NodeTrs& n = trs[size_t(node)];
            (p == AnimationPath::Weights ? pose.morphing : pose.moving)[size_t(node)] = 1;
            if (p == AnimationPath::Translation) {
                n.t = {v[0], v[1], v[2]};
                n.has_t = true;
            } else if (p == AnimationPath::Rotation) {
                n.r = {v[0], v[1], v[2], v[3]};
                n.has_r = true;
            } else if (p == AnimationPath::Scale) {
                n.s = {v[0], v[1], v[2]};
                n.has_s = true;
            } else {
                pose.weights[size_t(node)] = v;
            }
        }
    }
    // Global transforms over the whole node forest: joints outside the rendered scene are posed too.
    std::vector<int> parent(count, -1);
    for (size_t n = 0; n < count; ++n)
        for (const int c : model.nodes[n].children)
            if (c >= 0 && size_t(c) < count) parent[size_t(c)] = int(n);
    pose.world.resize(count);
    std::vector<uint8_t> done(count, 0);
    for (size_t n = 0; n < count; ++n) {
        // Walk up to the first node whose world is known (the validated graph has no cycle), then down.
        std::vector<int> chain;
        for (int k = int(n); k >= 0 && !done[size_t(k)]; k = parent[size_t(k)]) chain.push_back(k);
        for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
            const int k = *it, up = parent[size_t(k)];
            pose.world[size_t(k)] = (up >= 0 ? pose.world[size_t(up)] : Mat4d::identity()) * trs[size_t(k)].local();
            if (up >= 0) pose.moving[size_t(k)] |= pose.moving[size_t(up)];
            done[size_t(k)] = 1;
        }
    }
    return pose;
}

namespace {

/// Writes `property` ("offset", "rotation" or "scale") of the KHR_texture_transform of material
/// `g`'s texture `slot` (kTextureSlots), adding the extension object where the file has none.
/// Sets `member` of the JSON object `object` (made an object when it is not one) to a number or,
/// for several values, an array.
void set_member(tinygltf::Value& object, const std::string& member, const std::vector<double>& value) {
    tinygltf::Value::Object members = object.IsObject() ? object.Get<tinygltf::Value::Object>() : tinygltf::Value::Object{};
    if (value.size() == 1) {
        members[member] = tinygltf::Value(value[0]);
    } else {
        tinygltf::Value::Array a;
        for (const double x : value) a.emplace_back(x);
        members[member] = tinygltf::Value(std::move(a));
    }
    object = tinygltf::Value(std::move(members));
}

void set_texture_transform(tinygltf::Material& g, const std::string& slot, const std::string& property,
                           const std::vector<double>& value) {
    tinygltf::ExtensionMap* extensions = slot == "pbrMetallicRoughness/baseColorTexture"
                                             ? &g.pbrMetallicRoughness.baseColorTexture.extensions
                                         : slot == "pbrMetallicRoughness/metallicRoughnessTexture"
                                             ? &g.pbrMetallicRoughness.metallicRoughnessTexture.extensions
                                         : slot == "normalTexture"    ? &g.normalTexture.extensions
                                         : slot == "occlusionTexture" ? &g.occlusionTexture.extensions
                                                                      : &g.emissiveTexture.extensions;
    set_member((*extensions)["KHR_texture_transform"], property, value);
}

}  // namespace

void apply_pointer_values(const GltfPose& pose, tinygltf::Model& model) {
    for (const GltfPose::PointerValue& m : pose.values) {
        const std::vector<double> d(m.value.begin(), m.value.end());
        if (m.collection == GltfPose::Collection::Cameras) {
            model.cameras[size_t(m.index)].perspective.yfov = d[0];
            continue;
        }
        if (m.collection == GltfPose::Collection::Lights) {
            tinygltf::Light& l = model.lights[size_t(m.index)];
            if (m.property == "color") l.color = d;
            else l.intensity = d[0];
            continue;
        }
        tinygltf::Material& g = model.materials[size_t(m.index)];
        if (const size_t at = m.property.find(kTextureTransform); at != std::string::npos) {
            set_texture_transform(g, m.property.substr(0, at), m.property.substr(at + std::strlen(kTextureTransform)), d);
            continue;
        }
        if (m.property.rfind(kExtensions, 0) == 0) {
            // "extensions/KHR_materials_x/member": the extension object is added where the file has none.
            const std::string rest = m.property.substr(std::strlen(kExtensions));
            const size_t slash = rest.find('/');
            set_member(g.extensions[rest.substr(0, slash)], rest.substr(slash + 1), d);
            continue;
        }
        if (m.property == "pbrMetallicRoughness/baseColorFactor") g.pbrMetallicRoughness.baseColorFactor = d;
        else if (m.property == "pbrMetallicRoughness/metallicFactor") g.pbrMetallicRoughness.metallicFactor = d[0];
        else if (m.property == "pbrMetallicRoughness/roughnessFactor") g.pbrMetallicRoughness.roughnessFactor = d[0];
        else if (m.property == "emissiveFactor") g.emissiveFactor = d;
        else if (m.property == "alphaCutoff") g.alphaCutoff = d[0];
        else if (m.property == "normalTexture/scale") g.normalTexture.scale = d[0];
        else if (m.property == "occlusionTexture/strength") g.occlusionTexture.strength = d[0];
    }
}

bool deformed(const tinygltf::Model& model, int node, int primitive) {
    const tinygltf::Node& n = model.nodes[size_t(node)];
    if (n.mesh < 0) return false;
    const tinygltf::Primitive& p = model.meshes[size_t(n.mesh)].primitives[size_t(primitive)];
    return !p.targets.empty() || (n.skin >= 0 && p.attributes.count("JOINTS_0") && p.attributes.count("WEIGHTS_0"));
}

bool deforming(const tinygltf::Model& model, int node, const GltfPose& pose) {
    if (pose.morphing[size_t(node)]) return true;
    const int skin = model.nodes[size_t(node)].skin;
    if (skin < 0) return false;
    for (const int j : model.skins[size_t(skin)].joints)
        if (j >= 0 && size_t(j) < pose.moving.size() && pose.moving[size_t(j)]) return true;
    return false;
}

namespace {

/// Adds weights[t] times target t's `attribute` displacements into `out` (nothing without targets).
void add_targets(const tinygltf::Model& model, const tinygltf::Primitive& p, const std::vector<float>& weights,
                 const char* attribute, std::vector<Vec3d>& out) {
    for (size_t t = 0; t < p.targets.size() && t < weights.size(); ++t) {
        const auto it = p.targets[t].find(attribute);
        if (it == p.targets[t].end() || weights[t] == 0.f) continue;
        const double w = weights[t];
        for_each_element(accessor_data(model, it->second), [&](size_t i, const float* v) {
            if (i < out.size()) out[i] += Vec3d(v[0], v[1], v[2]) * w;
        });
    }
}

/// The skin's joint matrices global(joint) x inverseBindMatrix at the pose.
std::vector<Mat4d> joint_matrices(const tinygltf::Model& model, const std::string& path, int skin_index,
                                  const GltfPose& pose) {
    const tinygltf::Skin& skin = model.skins[size_t(skin_index)];
    const std::string sptr = fmt::format("/skins/{}", skin_index);
    std::vector<Mat4d> joint(skin.joints.size());
    std::vector<Mat4d> inverse_bind(skin.joints.size());
    if (skin.inverseBindMatrices >= 0) {
        if (size_t(skin.inverseBindMatrices) >= model.accessors.size())
            throw Error(file_loc(path, sptr + "/inverseBindMatrices"),
                        fmt::format("accessor {} does not exist", skin.inverseBindMatrices));
        const tinygltf::Accessor& a = model.accessors[size_t(skin.inverseBindMatrices)];
        if (a.type != TINYGLTF_TYPE_MAT4 || a.componentType != kFloat || a.count < skin.joints.size())
            throw Error(file_loc(path, sptr + "/inverseBindMatrices"),
                        fmt::format("must be a MAT4 FLOAT accessor of at least {} matrices (accessor {})",
                                    skin.joints.size(), skin.inverseBindMatrices));
        for_each_element(accessor_data(model, skin.inverseBindMatrices), [&](size_t i, const float* v) {
            if (i >= inverse_bind.size()) return;
            for (int c = 0; c < 4; ++c)
                for (int r = 0; r < 4; ++r) inverse_bind[i](r, c) = v[c * 4 + r];
        });
    }
    for (size_t j = 0; j < skin.joints.size(); ++j) {
        const int jn = skin.joints[j];
        if (jn < 0 || size_t(jn) >= model.nodes.size())
            throw Error(file_loc(path, fmt::format("{}/joints/{}", sptr, j)), fmt::format("node {} does not exist", jn));
        joint[j] = pose.world[size_t(jn)] * inverse_bind[j];
    }
    return joint;
}

/// Vertex `i`'s skin matrix (rows 0-2): the sum of its joints' matrices times their weights,
/// divided by the weights' sum when it is neither 0 nor 1.
Mat4d blend_joints(const SkinBinding& b, const std::vector<Mat4d>& joint, size_t i) {
    Mat4d out;
    out.m.fill(0.0);
    double sum = 0.0;
    const size_t n = b.influences;
    for (size_t k = 0; k < n; ++k) {
        const double w = b.weights[i * n + k];
        if (w == 0.0) continue;
        const Mat4d& J = joint[b.joints[i * n + k]];
        for (size_t e = 0; e < 12; ++e) out.m[e] += w * J.m[e];
        sum += w;
    }
    if (sum != 0.0 && sum != 1.0)
        for (size_t e = 0; e < 12; ++e) out.m[e] /= sum;
    return out;
}

/// The normal matrix's direction: the cofactors of the 3x3 block (the inverse transpose times the
/// determinant), signed by the determinant; zero for a singular block. Normalised by the caller.
Vec3d transform_normal(const Mat4d& m, const Vec3d& n) {
    const double c00 = m.m[5] * m.m[10] - m.m[6] * m.m[9], c01 = m.m[6] * m.m[8] - m.m[4] * m.m[10],
                 c02 = m.m[4] * m.m[9] - m.m[5] * m.m[8];
    const double c10 = m.m[2] * m.m[9] - m.m[1] * m.m[10], c11 = m.m[0] * m.m[10] - m.m[2] * m.m[8],
                 c12 = m.m[1] * m.m[8] - m.m[0] * m.m[9];
    const double c20 = m.m[1] * m.m[6] - m.m[2] * m.m[5], c21 = m.m[2] * m.m[4] - m.m[0] * m.m[6],
                 c22 = m.m[0] * m.m[5] - m.m[1] * m.m[4];
    const double det = m.m[0] * c00 + m.m[1] * c01 + m.m[2] * c02;
    const double s = det > 0.0 ? 1.0 : det < 0.0 ? -1.0 : 0.0;
    return Vec3d(c00 * n.x + c01 * n.y + c02 * n.z, c10 * n.x + c11 * n.y + c12 * n.z,
                 c20 * n.x + c21 * n.y + c22 * n.z) * s;
}

}  // namespace

SkinBinding skin_binding(const tinygltf::Model& model, const std::string& path, int node, int primitive,
                         size_t vertices) {
    SkinBinding b;
    const tinygltf::Node& n = model.nodes[size_t(node)];
    const tinygltf::Primitive& p = model.meshes[size_t(n.mesh)].primitives[size_t(primitive)];
    if (n.skin < 0 || !p.attributes.count("JOINTS_0") || !p.attributes.count("WEIGHTS_0")) return b;
    const size_t joint_count = model.skins[size_t(n.skin)].joints.size();
    b.skinned = true;
    int sets = 0;
    while (p.attributes.count(fmt::format("JOINTS_{}", sets)) && p.attributes.count(fmt::format("WEIGHTS_{}", sets)))
        ++sets;
    b.influences = size_t(sets) * 4;
    b.joints.assign(vertices * b.influences, 0);
    b.weights.assign(vertices * b.influences, 0.f);
    std::vector<std::array<float, 4>> joints_of, weights_of;
    for (int set = 0; set < sets; ++set) {
        const int ja = p.attributes.at(fmt::format("JOINTS_{}", set));
        const int wa = p.attributes.at(fmt::format("WEIGHTS_{}", set));
        joints_of.assign(vertices, {0, 0, 0, 0});
        weights_of.assign(vertices, {0, 0, 0, 0});
        for_each_element(accessor_data(model, ja), [&](size_t i, const float* v) {
            if (i < vertices) joints_of[i] = {v[0], v[1], v[2], v[3]};
        });
        for_each_element(accessor_data(model, wa), [&](size_t i, const float* v) {
            if (i < vertices) weights_of[i] = {v[0], v[1], v[2], v[3]};
        });
        for (size_t i = 0; i < vertices; ++i)
            for (size_t k = 0; k < 4; ++k) {
                const float w = weights_of[i][k];
                if (w == 0.f) continue;
                const float jf = joints_of[i][k];
                if (!(jf >= 0.f && size_t(jf) < joint_count))
                    throw Error(file_loc(path, fmt::format("/accessors/{}", ja)),
                                fmt::format("JOINTS_{} of vertex {} is {}, outside skin {}'s {} joints", set, i, jf,
                                            n.skin, joint_count));
                b.joints[i * b.influences + size_t(set) * 4 + k] = uint32_t(jf);
                b.weights[i * b.influences + size_t(set) * 4 + k] = w;
            }
    }
    return b;
}

void deform_mesh(Mesh& mesh, const tinygltf::Model& model, const std::string& path, int node, int primitive,
                 const GltfPose& pose, const SkinBinding* binding) {
    const tinygltf::Node& n = model.nodes[size_t(node)];
    const tinygltf::Primitive& p = model.meshes[size_t(n.mesh)].primitives[size_t(primitive)];
    const size_t nv = mesh.positions.size();
    // Morph targets (glTF 2.0 section 3.7.2.2): base + sum of weight x displacement, in double.
    const std::vector<float>& w = pose.weights[size_t(node)];
    const bool morphed = !p.targets.empty() && std::any_of(w.begin(), w.end(), [](float x) { return x != 0.f; });
    std::vector<Vec3d> pos, nrm, tan;
    if (morphed) {
        pos.resize(nv);
        nrm.resize(nv);
        tan.resize(nv);
        for (size_t i = 0; i < nv; ++i) pos[i] = Vec3d(mesh.positions[i]);
        for (size_t i = 0; i < mesh.normals.size() && i < nv; ++i) nrm[i] = Vec3d(mesh.normals[i]);
        for (size_t i = 0; i < mesh.tangents.size() && i < nv; ++i) tan[i] = Vec3d(mesh.tangents[i].xyz());
        add_targets(model, p, w, "POSITION", pos);
        if (!mesh.normals.empty()) add_targets(model, p, w, "NORMAL", nrm);
        if (!mesh.tangents.empty()) add_targets(model, p, w, "TANGENT", tan);
    }
    // The skin (section 3.7.3): world-space vertices; the mesh node's own transform does not apply.
    SkinBinding own;
    if (!binding) {
        own = skin_binding(model, path, node, primitive, nv);
        binding = &own;
    }
    const bool skinned = binding->skinned;
    const std::vector<Mat4d> joint = skinned ? joint_matrices(model, path, n.skin, pose) : std::vector<Mat4d>{};
    auto unit = [](const Vec3d& v, const Vec3f& fallback) {
        const double l = length(v);
        return l > 1e-30 && std::isfinite(l) ? Vec3f(v / l) : fallback;
    };
    const bool normals = mesh.normals.size() >= nv, tangents = mesh.tangents.size() >= nv;
    // Each vertex on its own: in parallel, the same numbers whatever the split.
    tbb::parallel_for(tbb::blocked_range<size_t>(0, nv, 4096), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) {
            Vec3d v = morphed ? pos[i] : Vec3d(mesh.positions[i]);
            Vec3d nv3 = !normals ? Vec3d(0.0) : morphed ? nrm[i] : Vec3d(mesh.normals[i]);
            Vec3d tv = !tangents ? Vec3d(0.0) : morphed ? tan[i] : Vec3d(mesh.tangents[i].xyz());
            if (skinned) {
                const Mat4d m = blend_joints(*binding, joint, i);
                v = m.apply_point(v);
                nv3 = transform_normal(m, nv3);
                tv = m.apply_vector(tv);
            }
            mesh.positions[i] = Vec3f(v);
            if (normals) mesh.normals[i] = unit(nv3, mesh.normals[i]);
            if (tangents) mesh.tangents[i] = Vec4f(unit(tv, mesh.tangents[i].xyz()), mesh.tangents[i].w);
        }
    });
}

void describe_animation(const tinygltf::Model& model, const std::vector<int>& posed, Scene& scene) {
    for (size_t a = 0; a < model.animations.size(); ++a) {
        const tinygltf::Animation& anim = model.animations[a];
        AnimationInfo info;
        info.name = animation_name(model, int(a));
        info.channels = anim.channels.size();
        info.duration = float(animation_duration(model, anim));
        std::set<std::string> kinds;
        for (const tinygltf::AnimationSampler& s : anim.samplers) kinds.insert(s.interpolation.empty() ? "LINEAR" : s.interpolation);
        for (const std::string& k : kinds) {
            if (!info.interpolations.empty()) info.interpolations += ',';
            info.interpolations += k;
        }
        info.posed = std::find(posed.begin(), posed.end(), int(a)) != posed.end();
        scene.animations.push_back(std::move(info));
    }
    for (size_t s = 0; s < model.skins.size(); ++s) {
        SkinInfo info;
        info.name = model.skins[s].name.empty() ? fmt::format("skin {}", s) : model.skins[s].name;
        info.joints = model.skins[s].joints.size();
        for (const Instance& inst : scene.instances)
            if (inst.node >= 0 && model.nodes[size_t(inst.node)].skin == int(s)) ++info.meshes;
        scene.skins.push_back(std::move(info));
    }
    for (size_t m = 0; m < model.meshes.size(); ++m) {
        const size_t targets = target_count(model.meshes[m]);
        if (targets == 0) continue;
        MorphInfo info;
        info.mesh = model.meshes[m].name.empty() ? fmt::format("mesh {}", m) : model.meshes[m].name;
        info.targets = targets;
        for (const double w : model.meshes[m].weights) info.default_weights.push_back(float(w));
        scene.morphs.push_back(std::move(info));
    }
}

}  // namespace whitted
