// Scene file (JSON) -> Scene (docs/scene-format.md).
//
// Pipeline: read the file -> parse JSON with locations (scene_file_json.cpp) -> check the
// top-level keys and the version -> textures -> materials -> cameras -> objects (spheres,
// infinite planes, generated meshes) -> lights -> includes (glTF through import_gltf, appended
// with indices remapped and the include transform applied) -> ambient and render settings ->
// defaults (material, camera, light) -> render.camera checked against the cameras.
// Every failure is a whitted::Error naming the file, the JSON pointer of the offending value and
// its line:column; unknown keys and names come with a "did you mean" suggestion.

#include "importers/scene_file.h"
#include "importers/environment_image.h"

#include <algorithm>
#include <charconv>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <map>
#include <numbers>
#include <optional>

#include <fmt/format.h>

#include "importers/image_decode.h"
#include "importers/mesh_normals.h"
#include "importers/mesh_numbers.h"
#include "importers/scene_defaults.h"
#include "importers/scene_file_geometry.h"
#include "importers/scene_file_image.h"
#include "importers/scene_file_json.h"
#include "importers/warning_log.h"
#include "core/log.h"
#include "core/error.h"
#include "shading/texture_sampling.h"

namespace whitted {

namespace {

using scene_file::Json;
using scene_file::JsonDocument;
namespace fs = std::filesystem;

/// The parsed JSON tree takes up to about this many bytes per byte of text (a value is 16 bytes,
/// "0," is 2): files larger than max_memory / kJsonBytesPerByte are refused before parsing.
constexpr size_t kJsonBytesPerByte = 16;
constexpr double kDegrees = std::numbers::pi / 180.0;

/// A closed range of accepted numbers, with how to say it in a message.
struct Range {
    double lo = -HUGE_VAL, hi = HUGE_VAL;
    bool lo_open = false, hi_open = false;

    bool contains(double v) const {
        return std::isfinite(v) && (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
    }
    std::string text(const char* noun = "number") const {
        const bool has_lo = lo != -HUGE_VAL, has_hi = hi != HUGE_VAL;
        if (has_lo && has_hi)
            return fmt::format("a {} in {}{}, {}{}", noun, lo_open ? "(" : "[", lo, hi, hi_open ? ")" : "]");
        if (has_lo) return fmt::format("a {} {} {}", noun, lo_open ? ">" : ">=", lo);
        if (has_hi) return fmt::format("a {} {} {}", noun, hi_open ? "<" : "<=", hi);
        return fmt::format("a finite {}", noun);
    }
};
constexpr Range kAny{};
constexpr Range kNonNegative{0.0};
constexpr Range kPositive{0.0, HUGE_VAL, true};

std::string join(const std::vector<std::string>& names) {
    std::string s;
    for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
    return s;
}

std::string lower_ext(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    for (char& c : ext) c = char(std::tolower((unsigned char)c));
    return ext;
}

/// Rough bytes a mesh holds (memory budget).
size_t mesh_bytes(size_t vertices, size_t indices, size_t per_vertex) {
    return vertices * per_vertex + indices * sizeof(uint32_t) + sizeof(Mesh) + sizeof(Instance);
}

size_t scene_bytes(const Scene& s) {
    size_t n = 0;
    for (const Mesh& m : s.meshes)
        n += m.positions.size() * sizeof(Vec3f) + m.normals.size() * sizeof(Vec3f) +
             m.tangents.size() * sizeof(Vec4f) + (m.uv0.size() + m.uv1.size()) * sizeof(Vec2f) +
             m.colors.size() * sizeof(Vec4f) + m.indices.size() * sizeof(uint32_t);
    n += s.instances.size() * (sizeof(Instance) + 32);
    for (const Texture& t : s.textures)
        for (const MipLevel& l : t.levels) n += l.texels.size();
    return n;
}

void shift(TextureRef& ref, int32_t offset) {
    if (ref.valid()) ref.texture += offset;
}

/// Reads one scene file into a Scene.
class SceneFileReader {
public:
    SceneFileReader(const JsonDocument& doc, const ImportOptions& options) : m_doc(doc), m_options(options) {
        std::error_code ec;
        const fs::path abs = fs::absolute(doc.path, ec);
        m_dir = (ec ? fs::path(doc.path) : abs).lexically_normal().parent_path();
        m_bytes = doc.text.size() * kJsonBytesPerByte;
    }

    Scene run() {
        m_scene.source = m_doc.path;
        const Json& root = m_doc.root;
        check_object(root, "", "the scene file",
                     {"$schema", "comment", "version", "render", "ambient", "environment", "camera", "textures",
                      "materials", "objects", "include", "lights"});
        read_version(root);
        if (const Json* t = member(root, "textures")) read_textures(*t);
        if (const Json* m = member(root, "materials")) read_materials(*m);
        if (const Json* c = member(root, "camera")) read_cameras(*c);
        if (const Json* o = member(root, "objects")) read_objects(*o);
        if (const Json* l = member(root, "lights")) read_lights(*l);
        if (const Json* i = member(root, "include")) read_includes(*i);
        if (const Json* a = member(root, "ambient")) m_scene.settings.ambient = color(*a, "/ambient");
        if (const Json* r = member(root, "render")) read_render(*r);
        if (const Json* e = member(root, "environment")) read_environment(*e);

        if (m_scene.materials.empty()) default_material();
        add_scene_defaults(m_scene, m_options, m_warnings);
        if (m_scene.settings.camera && size_t(*m_scene.settings.camera) >= m_scene.cameras.size())
            fail("/render/camera", "camera {} requested but the scene has {} camera(s) (indices from 0)",
                 *m_scene.settings.camera, m_scene.cameras.size());
        m_warnings.flush_to(m_scene);
        return std::move(m_scene);
    }

private:
    // ---- errors -------------------------------------------------------------------------------
    template <typename... Args>
    [[noreturn]] void fail(const std::string& ptr, fmt::format_string<Args...> f, Args&&... args) const {
        throw Error(scene_file::locate(m_doc, ptr), fmt::format(f, std::forward<Args>(args)...));
    }
    /// Located at the member's key rather than its value (unknown and duplicate keys).
    template <typename... Args>
    [[noreturn]] void fail_key(const std::string& ptr, fmt::format_string<Args...> f, Args&&... args) const {
        throw Error(scene_file::locate(m_doc, ptr, true), fmt::format(f, std::forward<Args>(args)...));
    }
    [[noreturn]] void expected(const Json& v, const std::string& ptr, const std::string& what) const {
        fail(ptr, "expected {}, got {}", what, scene_file::describe(v));
    }
    static std::string sub(const std::string& ptr, std::string_view key) {
        return ptr + "/" + scene_file::pointer_token(key);
    }
    static std::string sub(const std::string& ptr, size_t index) { return fmt::format("{}/{}", ptr, index); }

    /// " (did you mean 'x'?)" or " (expected one of: a, b)" for an unknown name.
    static std::string suggestion(const std::string& name, const std::vector<std::string>& known, bool list = true) {
        const std::string close = scene_file::closest_match(name, known);
        if (!close.empty()) return fmt::format(" (did you mean '{}'?)", close);
        if (list && !known.empty() && known.size() <= 24) return fmt::format(" (expected one of: {})", join(known));
        return "";
    }

    // ---- typed access -------------------------------------------------------------------------
    static const Json* member(const Json& obj, const char* key) {
        if (!obj.is_object()) return nullptr;
        auto it = obj.find(key);
        return it == obj.end() ? nullptr : &*it;
    }

    /// `v` must be an object whose keys are all in `allowed`.
    void check_object(const Json& v, const std::string& ptr, const std::string& what,
                      std::initializer_list<const char*> allowed) const {
        if (!v.is_object()) expected(v, ptr, "an object (" + what + ")");
        std::vector<std::string> names(allowed.begin(), allowed.end());
        for (const auto& [key, value] : v.items()) {
            if (std::find(names.begin(), names.end(), key) != names.end()) continue;
            names.erase(std::remove(names.begin(), names.end(), "$schema"), names.end());
            names.erase(std::remove(names.begin(), names.end(), "comment"), names.end());
            fail_key(sub(ptr, key), "unknown key '{}' in {}{}", key, what, suggestion(key, names));
        }
    }

    const Json& require(const Json& obj, const char* key, const std::string& ptr, const std::string& what,
                        const std::string& expect) const {
        const Json* v = member(obj, key);
        if (v == nullptr) fail(ptr, "missing key '{}' in {} (expected {})", key, what, expect);
        return *v;
    }

    double number(const Json& v, const std::string& ptr, const Range& range = kAny) const {
        if (!v.is_number()) expected(v, ptr, range.text());
        const double d = v.get<double>();
        if (!range.contains(d)) expected(v, ptr, range.text());
        // The renderer works in float: larger values would become infinities there.
        if (std::fabs(d) > double(std::numeric_limits<float>::max()))
            fail(ptr, "expected {} within the float range (|x| <= 3.4e38), got {}", range.text(), scene_file::describe(v));
        return d;
    }

    int integer(const Json& v, const std::string& ptr, int lo, int hi) const {
        const std::string what = hi == INT32_MAX ? fmt::format("an integer >= {}", lo)
                                                 : fmt::format("an integer in [{}, {}]", lo, hi);
        if (!v.is_number()) expected(v, ptr, what);
        const double d = v.get<double>();
        if (!(d >= lo && d <= hi) || d != std::floor(d)) expected(v, ptr, what);
        return int(d);
    }

    bool boolean(const Json& v, const std::string& ptr) const {
        if (!v.is_boolean()) expected(v, ptr, "true or false");
        return v.get<bool>();
    }

    std::string string(const Json& v, const std::string& ptr, bool allow_empty = false) const {
        if (!v.is_string() || (!allow_empty && v.get_ref<const std::string&>().empty()))
            expected(v, ptr, allow_empty ? "a string" : "a non-empty string");
        return v.get<std::string>();
    }

    /// One of `choices`, with a suggestion when it is not.
    std::string choice(const Json& v, const std::string& ptr, const std::vector<std::string>& choices) const {
        std::string quoted;
        for (const std::string& c : choices) quoted += (quoted.empty() ? "\"" : ", \"") + c + "\"";
        if (!v.is_string()) expected(v, ptr, "one of " + quoted);
        const std::string s = v.get<std::string>();
        if (std::find(choices.begin(), choices.end(), s) == choices.end())
            fail(ptr, "expected one of {}, got {}{}", quoted, scene_file::describe(v), suggestion(s, choices, false));
        return s;
    }

    Vec3d vec3(const Json& v, const std::string& ptr, const Range& range = kAny) const {
        const std::string what = range.lo == kAny.lo ? "an array of 3 numbers" : "an array of 3 numbers, each " + range.text();
        if (!v.is_array() || v.size() != 3) expected(v, ptr, what);
        Vec3d r;
        for (int k = 0; k < 3; ++k) r[k] = number(v[size_t(k)], sub(ptr, size_t(k)), range);
        return r;
    }

    /// A unit direction: 3 numbers, not all zero.
    Vec3d direction(const Json& v, const std::string& ptr) const {
        const Vec3d d = vec3(v, ptr);
        const double len = length(d);
        if (!(len > 0) || !std::isfinite(len)) fail(ptr, "expected a direction (a non-zero vector), got (0, 0, 0)");
        return d / len;
    }

    /// A linear RGB color: a number (gray) or an array of 3 numbers, each >= 0.
    Color color(const Json& v, const std::string& ptr) const {
        if (v.is_number()) return Color(float(number(v, ptr, kNonNegative)));
        if (!v.is_array() || v.size() != 3)
            expected(v, ptr, "a color: a number >= 0 (gray) or an array of 3 numbers >= 0 (linear RGB)");
        Color c;
        for (int k = 0; k < 3; ++k) c[k] = float(number(v[size_t(k)], sub(ptr, size_t(k)), kNonNegative));
        if (!is_finite(c)) fail(ptr, "color component out of the float range");
        return c;
    }

    // ---- top level ----------------------------------------------------------------------------
    void read_version(const Json& root) {
        const Json& v = require(root, "version", "", "the scene file", fmt::format("\"version\": {}", kSceneFileVersion));
        if (!v.is_number() || v.get<double>() != kSceneFileVersion)
            fail("/version", "unsupported scene file version {} (this whitted reads version {})",
                 scene_file::describe(v), kSceneFileVersion);
    }

    /// Object-valued section: each member in file order (nlohmann sorts keys).
    template <typename F>
    void for_each_named(const Json& section, const std::string& ptr, const std::vector<std::string>& order,
                        const char* what, F&& fn) {
        if (!section.is_object()) expected(section, ptr, fmt::format("an object of {} by name", what));
        for (const std::string& name : order) {
            auto it = section.find(name);
            if (it != section.end()) fn(name, *it, sub(ptr, name));
        }
    }

    // ---- transforms ---------------------------------------------------------------------------
    /// {"translate", "rotate", "scale"} composed as T * R * S, or {"matrix"} (16 numbers,
    /// column-major, affine).
    Mat4d transform(const Json& v, const std::string& ptr) const {
        check_object(v, ptr, "a transform", {"translate", "rotate", "scale", "matrix", "comment"});
        Mat4d m;
        if (const Json* mat = member(v, "matrix")) {
            const std::string mp = sub(ptr, "matrix");
            for (const char* other : {"translate", "rotate", "scale"})
                if (member(v, other) != nullptr)
                    fail_key(sub(ptr, other), "'{}' cannot be combined with 'matrix' (give a matrix, or translate/rotate/scale)",
                             other);
            if (!mat->is_array() || mat->size() != 16) expected(*mat, mp, "an array of 16 numbers (column-major 4x4)");
            for (int c = 0; c < 4; ++c)
                for (int r = 0; r < 4; ++r) m(r, c) = number((*mat)[size_t(c * 4 + r)], sub(mp, size_t(c * 4 + r)));
            if (m(3, 0) != 0 || m(3, 1) != 0 || m(3, 2) != 0 || m(3, 3) != 1)
                fail(mp, "the matrix is not affine: its last row must be (0, 0, 0, 1) (elements 3, 7, 11, 15)");
        } else {
            Mat4d t, r, s;
            if (const Json* tr = member(v, "translate")) t = Mat4d::translate(vec3(*tr, sub(ptr, "translate")));
            if (const Json* ro = member(v, "rotate")) r = rotation(*ro, sub(ptr, "rotate"));
            if (const Json* sc = member(v, "scale")) {
                const std::string sp = sub(ptr, "scale");
                s = Mat4d::scale(sc->is_number() ? Vec3d(number(*sc, sp)) : vec3(*sc, sp));
            }
            m = t * r * s;
        }
        const double det = m.det3();
        if (!(std::fabs(det) > 1e-30) || !std::isfinite(det) || !m.is_finite())
            fail(ptr, "the transform is singular (a scale of 0?) or not finite");
        return m;
    }

    /// [deg, ax, ay, az], or a list of them applied in order (the first one first).
    Mat4d rotation(const Json& v, const std::string& ptr) const {
        const char* what = "[angle in degrees, axis x, y, z] or a list of them";
        if (!v.is_array()) expected(v, ptr, what);
        if (!v.empty() && v[0].is_array()) {
            Mat4d r;
            for (size_t i = 0; i < v.size(); ++i) r = rotation(v[i], sub(ptr, i)) * r;
            return r;
        }
        if (v.size() != 4) expected(v, ptr, what);
        const double deg = number(v[0], sub(ptr, size_t(0)));
        Vec3d axis;
        for (int k = 0; k < 3; ++k) axis[k] = number(v[size_t(k + 1)], sub(ptr, size_t(k + 1)));
        const double len = length(axis);
        if (!(len > 0)) fail(ptr, "the rotation axis is (0, 0, 0)");
        axis = axis / len;
        const double h = 0.5 * deg * kDegrees;
        const double sh = std::sin(h);
        return Mat4d::rotate(axis.x * sh, axis.y * sh, axis.z * sh, std::cos(h));
    }

    // ---- textures -----------------------------------------------------------------------------
    struct NamedTexture {
        int32_t index = -1;
        TextureRef ref;  ///< what a material referencing it gets (uv set, transform)
    };

    void read_textures(const Json& section) {
        for_each_named(section, "/textures", m_doc.texture_order, "textures",
                       [&](const std::string& name, const Json& t, const std::string& ptr) {
                           if (!t.is_object()) expected(t, ptr, "an object (a texture)");
                           const Json& type = require(t, "type", ptr, "a texture", "\"checker\" or \"image\"");
                           const std::string kind = choice(type, sub(ptr, "type"), {"checker", "image"});
                           Texture tex;
                           tex.name = name;
                           NamedTexture named;
                           if (kind == "checker")
                               read_checker(t, ptr, tex);
                           else
                               read_image_texture(t, ptr, tex);
                           if (const Json* uv = member(t, "uv_set")) named.ref.uv_set = uint32_t(integer(*uv, sub(ptr, "uv_set"), 0, 1));
                           if (const Json* x = member(t, "uv_transform"))
                               named.ref.transform = uv_transform(*x, sub(ptr, "uv_transform"));
                           named.index = int32_t(m_scene.textures.size());
                           named.ref.texture = named.index;
                           m_scene.textures.push_back(std::move(tex));
                           m_textures.emplace(name, named);
                           m_texture_names.push_back(name);
                       });
    }

    void read_checker(const Json& t, const std::string& ptr, Texture& tex) {
        check_object(t, ptr, "a checker texture", {"type", "colors", "size", "space", "uv_set", "uv_transform", "comment"});
        tex.kind = TextureKind::Checker;
        tex.image = -1;
        if (const Json* c = member(t, "colors")) {
            const std::string cp = sub(ptr, "colors");
            if (!c->is_array() || c->size() != 2) expected(*c, cp, "an array of 2 colors");
            tex.checker.color_a = color((*c)[0], sub(cp, size_t(0)));
            tex.checker.color_b = color((*c)[1], sub(cp, size_t(1)));
        }
        if (const Json* s = member(t, "size")) tex.checker.size = float(number(*s, sub(ptr, "size"), kPositive));
        if (!(tex.checker.size > 0.f)) fail(sub(ptr, "size"), "the size is too small for a float");
        if (const Json* s = member(t, "space")) tex.checker.world_space = choice(*s, sub(ptr, "space"), {"uv", "world"}) == "world";
    }

    void read_image_texture(const Json& t, const std::string& ptr, Texture& tex) {
        check_object(t, ptr, "an image texture",
                     {"type", "file", "srgb", "wrap", "filter", "mipmaps", "uv_set", "uv_transform", "comment"});
        tex.kind = TextureKind::Image;
        tex.image = -1;
        const std::string fp = sub(ptr, "file");
        const std::string file = string(require(t, "file", ptr, "an image texture", "a file name"), fp);
        const fs::path resolved = resolve(file, fp, "image");
        if (const Json* w = member(t, "wrap")) {
            const std::string m = choice(*w, sub(ptr, "wrap"), {"repeat", "clamp", "mirror"});
            tex.wrap_s = tex.wrap_t = m == "clamp" ? WrapMode::ClampToEdge : m == "mirror" ? WrapMode::MirroredRepeat : WrapMode::Repeat;
        }
        if (const Json* f = member(t, "filter"))
            tex.mag_filter = tex.min_filter =
                choice(*f, sub(ptr, "filter"), {"linear", "nearest"}) == "nearest" ? FilterMode::Nearest : FilterMode::Linear;
        if (const Json* m = member(t, "mipmaps")) tex.use_mips = boolean(*m, sub(ptr, "mipmaps"));
        tex.srgb = true;
        const Json* srgb = member(t, "srgb");
        if (srgb != nullptr) tex.srgb = boolean(*srgb, sub(ptr, "srgb"));
        if (!m_options.load_textures) return;
        const size_t budget = m_options.max_memory > m_bytes ? m_options.max_memory - m_bytes : 0;
        LoadedImage img = load_image_file(resolved.string(), budget, scene_file::locate(m_doc, fp));
        if (img.float_data) {
            // Linear floating-point data stored sRGB-encoded in 8 bits (better than linear 8-bit).
            if (srgb != nullptr && !tex.srgb)
                m_scene.warn(fmt::format("{}: '{}' holds floating-point (linear) data: \"srgb\": false ignored", fp, file));
            tex.srgb = true;
        }
        m_bytes += decoded_image_bytes(img.level.width, img.level.height);
        tex.levels.assign(1, std::move(img.level));
        if (tex.use_mips) build_mip_levels(tex);
    }

    TextureTransform uv_transform(const Json& v, const std::string& ptr) const {
        check_object(v, ptr, "a UV transform", {"offset", "rotation", "scale", "comment"});
        TextureTransform x;
        auto vec2 = [&](const Json& a, const std::string& p) {
            if (a.is_number()) {
                const float s = float(number(a, p));
                return Vec2f{s, s};
            }
            if (!a.is_array() || a.size() != 2) expected(a, p, "a number or an array of 2 numbers");
            return Vec2f{float(number(a[0], sub(p, size_t(0)))), float(number(a[1], sub(p, size_t(1))))};
        };
        if (const Json* o = member(v, "offset")) x.offset = vec2(*o, sub(ptr, "offset"));
        if (const Json* r = member(v, "rotation")) x.rotation = float(number(*r, sub(ptr, "rotation")) * kDegrees);
        if (const Json* s = member(v, "scale")) x.scale = vec2(*s, sub(ptr, "scale"));
        return x;
    }

    /// A texture name used by a material key.
    const NamedTexture& texture_named(const Json& v, const std::string& ptr) const {
        const std::string name = v.get<std::string>();
        auto it = m_textures.find(name);
        if (it == m_textures.end()) {
            if (m_textures.empty())
                fail(ptr, "unknown texture '{}': the file defines no textures (expected a color: a number or an "
                          "array of 3 numbers, or the name of an entry of \"textures\")",
                     name);
            fail(ptr, "unknown texture '{}'{}", name, suggestion(name, m_texture_names));
        }
        return it->second;
    }

    // ---- materials ----------------------------------------------------------------------------
    void read_materials(const Json& section) {
        for_each_named(section, "/materials", m_doc.material_order, "materials",
                       [&](const std::string& name, const Json& m, const std::string& ptr) {
                           m_material_index.emplace(name, uint32_t(m_scene.materials.size()));
                           m_material_names.push_back(name);
                           m_scene.materials.push_back(read_material(name, m, ptr));
                       });
    }

    Material read_material(const std::string& name, const Json& v, const std::string& ptr) {
        check_object(v, ptr, "a material",
                     {"kd", "color", "ka", "ks", "highlight", "n", "kr", "kt", "ior", "thin", "emission", "absorption",
                      "comment"});
        Material m;
        m.name = name;
        m.model = MaterialModel::Classic;
        WhittedCoeffs& c = m.classic;
        c.n = 32.f;
        c.thin = false;
        c.ior = 1.5f;

        // kd (alias color) and ka: a color, or a texture name (coefficient 1, texture multiplies both).
        const Json* kd = member(v, "kd");
        std::string kd_key = "kd";
        if (const Json* col = member(v, "color")) {
            if (kd != nullptr)
                fail_key(sub(ptr, "color"), "'color' is another name for 'kd': give one of them, not both");
            kd = col;
            kd_key = "color";
        }
        int32_t texture = -1;
        std::string texture_key;
        TextureRef ref;
        auto color_or_texture = [&](const Json& x, const std::string& key) -> Color {
            const std::string p = sub(ptr, key);
            if (!x.is_string()) return color(x, p);
            const NamedTexture& t = texture_named(x, p);
            if (texture >= 0 && texture != t.index)
                fail(p, "'{}' names texture '{}' but '{}' names '{}': a material has one color texture (it multiplies "
                        "kd and ka)",
                     key, x.get<std::string>(), texture_key, m_scene.textures[size_t(texture)].name);
            texture = t.index;
            texture_key = key;
            ref = t.ref;
            return Color(1.f);
        };
        if (kd != nullptr) c.kd = color_or_texture(*kd, kd_key);
        c.ka = c.kd;  // ka defaults to kd (its texture too)
        if (const Json* ka = member(v, "ka")) c.ka = color_or_texture(*ka, "ka");
        m.classic_color_texture = ref;

        // Whitted's (1980) single ks weights the highlight and the mirror ray; kr and highlight
        // set them apart.
        auto coeff = [&](const char* key, Color& out) {
            if (const Json* x = member(v, key)) {
                if (x->is_string())
                    expected(*x, sub(ptr, key),
                             "a color: a number >= 0 or an array of 3 numbers >= 0 (only kd/color and ka take a texture)");
                out = color(*x, sub(ptr, key));
                return true;
            }
            return false;
        };
        if (coeff("ks", c.ks)) c.kr = c.ks;
        coeff("kr", c.kr);
        coeff("highlight", c.ks);
        coeff("kt", c.kt);
        coeff("emission", c.emission);
        coeff("absorption", c.absorption);
        if (const Json* n = member(v, "n")) c.n = float(number(*n, sub(ptr, "n"), kPositive));
        if (const Json* ior = member(v, "ior")) c.ior = float(number(*ior, sub(ptr, "ior"), kPositive));
        if (const Json* thin = member(v, "thin")) c.thin = boolean(*thin, sub(ptr, "thin"));
        if (!(c.n > 0.f) || !std::isfinite(c.n)) fail(sub(ptr, "n"), "n is out of the float range");
        if (!(c.ior > 0.f) || !std::isfinite(c.ior)) fail(sub(ptr, "ior"), "ior is out of the float range");

        // Energy: a hint, not an error (Whitted's coefficients are the user's to choose).
        const Color sum = c.kd + c.kr + c.kt;
        if (max_component(sum) > 1.f + 1e-3f) {
            const int ch = sum.x >= sum.y && sum.x >= sum.z ? 0 : sum.y >= sum.z ? 1 : 2;
            m_warnings.add("energy:" + name,
                           fmt::format("{}: material '{}': kd + kr + kt = {:.3g} > 1 ({} channel): the surface returns "
                                       "more light than it receives",
                                       ptr, name, sum[ch], ch == 0 ? "red" : ch == 1 ? "green" : "blue"));
        }
        return m;
    }

    /// Index of the built-in default material (added once), or the file's own "default".
    uint32_t default_material() {
        if (auto it = m_material_index.find("default"); it != m_material_index.end()) return it->second;
        if (m_default_material < 0) {
            Material m;
            m.name = "default";
            m.model = MaterialModel::Classic;
            m.classic.kd = m.classic.ka = Color(0.8f);
            m.classic.n = 32.f;
            m.classic.thin = false;
            m_default_material = int(m_scene.materials.size());
            m_scene.materials.push_back(std::move(m));
        }
        return uint32_t(m_default_material);
    }

    uint32_t material_ref(const Json& obj, const std::string& ptr) {
        const Json* v = member(obj, "material");
        if (v == nullptr) return default_material();
        const std::string p = sub(ptr, "material");
        const std::string name = string(*v, p);
        return material_named(name, p);
    }

    uint32_t material_named(const std::string& name, const std::string& p) const {
        auto it = m_material_index.find(name);
        if (it == m_material_index.end()) {
            if (m_material_names.empty()) fail(p, "unknown material '{}': the file defines no materials", name);
            fail(p, "unknown material '{}'{}", name, suggestion(name, m_material_names));
        }
        return it->second;
    }

    // ---- cameras ------------------------------------------------------------------------------
    void read_cameras(const Json& v) {
        if (v.is_array()) {
            for (size_t i = 0; i < v.size(); ++i)
                m_scene.cameras.push_back(read_camera(v[i], sub("/camera", i), fmt::format("camera {}", i)));
        } else {
            m_scene.cameras.push_back(read_camera(v, "/camera", "camera"));
        }
    }

    Camera read_camera(const Json& v, const std::string& ptr, const std::string& default_name) {
        if (!v.is_object()) expected(v, ptr, "an object (a camera)");
        std::string type = "perspective";
        if (const Json* t = member(v, "type")) type = choice(*t, sub(ptr, "type"), {"perspective", "orthographic"});
        const bool persp = type == "perspective";
        if (persp)
            check_object(v, ptr, "a perspective camera",
                         {"type", "name", "position", "look_at", "direction", "up", "fov", "znear", "zfar", "comment"});
        else
            check_object(v, ptr, "an orthographic camera",
                         {"type", "name", "position", "look_at", "direction", "up", "size", "znear", "zfar", "comment"});
        Camera c;
        c.name = default_name;
        if (const Json* n = member(v, "name")) c.name = string(*n, sub(ptr, "name"));
        const Vec3d eye = vec3(require(v, "position", ptr, "a camera", "an array of 3 numbers"), sub(ptr, "position"));
        Vec3d forward{0, 0, -1};
        const Json* look = member(v, "look_at");
        const Json* dir = member(v, "direction");
        if (look != nullptr && dir != nullptr)
            fail_key(sub(ptr, "direction"), "give 'look_at' or 'direction', not both");
        if (look != nullptr) {
            const Vec3d target = vec3(*look, sub(ptr, "look_at"));
            forward = normalize(target - eye);
            if (!(length(forward) > 0)) fail(sub(ptr, "look_at"), "look_at is the camera position: no view direction");
        } else if (dir != nullptr) {
            forward = direction(*dir, sub(ptr, "direction"));
        }
        Vec3d up{0, 1, 0};
        if (const Json* u = member(v, "up")) up = direction(*u, sub(ptr, "up"));
        // Camera frame: -Z looks along `forward`, +Y as close to `up` as possible (glTF convention).
        const Vec3d z = -forward;
        const Vec3d x = normalize(cross(up, z));
        if (!(length(x) > 0.5))
            fail(member(v, "up") ? sub(ptr, "up") : ptr,
                 "the up vector is parallel to the view direction: give an \"up\" that is not");
        const Vec3d y = cross(z, x);
        for (int r = 0; r < 3; ++r) {
            c.world_from_camera(r, 0) = x[r];
            c.world_from_camera(r, 1) = y[r];
            c.world_from_camera(r, 2) = z[r];
            c.world_from_camera(r, 3) = eye[r];
        }
        if (persp) {
            c.type = CameraType::Perspective;
            double fov = 45.0;
            if (const Json* f = member(v, "fov")) fov = number(*f, sub(ptr, "fov"), Range{0.0, 180.0, true, true});
            c.yfov = fov * kDegrees;
        } else {
            c.type = CameraType::Orthographic;
            double size = 2.0;
            if (const Json* s = member(v, "size")) size = number(*s, sub(ptr, "size"), kPositive);
            c.ymag = c.xmag = 0.5 * size;  // xmag follows the image aspect at render time
        }
        c.aspect = 0.0;
        if (const Json* n = member(v, "znear")) c.znear = number(*n, sub(ptr, "znear"), kPositive);
        if (const Json* f = member(v, "zfar")) {
            c.zfar = number(*f, sub(ptr, "zfar"), kPositive);
            if (!(c.zfar > c.znear)) fail(sub(ptr, "zfar"), "zfar ({}) must be greater than znear ({})", c.zfar, c.znear);
        }
        return c;
    }

    // ---- objects ------------------------------------------------------------------------------
    void read_objects(const Json& v) {
        if (!v.is_array()) expected(v, "/objects", "an array of objects");
        std::map<std::string, int> counts;
        int& sphere_count = counts["sphere"];
        // Most large files are spheres: one allocation instead of a doubling series (a million
        // spheres held up to twice their size while the vector grew).
        m_scene.spheres.reserve(m_scene.spheres.size() + m_doc.objects.size());
        for (size_t i = 0; i < m_doc.objects.size(); ++i) {
            const auto [begin, end] = m_doc.objects[i];
            const std::string_view text = std::string_view(m_doc.text).substr(begin, end - begin);
            if (scene_file::SphereFields f; scene_file::scan_sphere(text, f) && add_scanned_sphere(f, sphere_count))
                continue;
            const std::string ptr = sub("/objects", i);
            Json o;  // an exporter's plain mesh without nlohmann's lexer (scan_mesh), else the general parse
            if (!scene_file::scan_mesh(text, o)) o = scene_file::parse_object(m_doc, i);
            if (!o.is_object()) expected(o, ptr, "an object (sphere, cylinder, cone, disc, plane, box or mesh)");
            const std::string type = choice(
                require(o, "type", ptr, "an object",
                        "\"sphere\", \"cylinder\", \"cone\", \"disc\", \"plane\", \"box\" or \"mesh\""),
                sub(ptr, "type"), {"sphere", "cylinder", "cone", "disc", "plane", "box", "mesh"});
            std::string name = fmt::format("{} {}", type, counts[type]++);
            if (const Json* n = member(o, "name")) name = string(*n, sub(ptr, "name"));
            if (type == "sphere") read_sphere(o, ptr, name);
            else if (type == "cylinder" || type == "cone" || type == "disc") read_quadric(o, ptr, name, type);
            else if (type == "plane") read_plane(o, ptr, name);
            else if (type == "box") read_box(o, ptr, name);
            else read_mesh(o, ptr, name);
        }
    }

    /// The fast path of read_sphere (no DOM, no pointers): a sphere scan_sphere read whose values
    /// pass read_sphere's checks, with the same result; false leaves it to the general path.
    bool add_scanned_sphere(const scene_file::SphereFields& f, int& count) {
        const double limit = double(std::numeric_limits<float>::max());
        for (const double c : f.center)
            if (!(std::fabs(c) <= limit)) return false;
        if (!(f.radius > 0 && f.radius <= limit)) return false;
        uint32_t material = 0;
        if (f.has_material) {
            const auto it = m_material_index.find(f.material);
            if (it == m_material_index.end()) return false;
            material = it->second;
        } else {
            material = default_material();
        }
        Sphere s;
        if (f.has_name) {
            s.name = std::string(f.name);
        } else {  // "sphere <count>", without a format call per sphere (a million in a large file)
            char buf[32] = "sphere ";
            s.name.assign(buf, std::to_chars(buf + 7, buf + sizeof buf, count).ptr);
        }
        ++count;
        s.center = Vec3d(f.center[0], f.center[1], f.center[2]);
        s.radius = f.radius;
        s.material = material;
        m_scene.spheres.push_back(std::move(s));
        return true;
    }

    void read_sphere(const Json& o, const std::string& ptr, const std::string& name) {
        check_object(o, ptr, "a sphere", {"type", "name", "center", "radius", "material", "comment"});
        Sphere s;
        s.name = name;
        s.center = vec3(require(o, "center", ptr, "a sphere", "an array of 3 numbers"), sub(ptr, "center"));
        s.radius = number(require(o, "radius", ptr, "a sphere", "a number > 0"), sub(ptr, "radius"), kPositive);
        s.material = material_ref(o, ptr);
        m_scene.spheres.push_back(std::move(s));
    }

    /// Cylinder {base, apex, radius, open}, cone {base, base_radius, apex, apex_radius, open} (NFF's
    /// cone: a truncated cone, a point at an end of radius 0) and disc {center, normal, radius,
    /// inner_radius}, each with a material and a transform (Scene::Quadric).
    void read_quadric(const Json& o, const std::string& ptr, const std::string& name, const std::string& type) {
        QuadricKind kind = QuadricKind::Disc;
        Vec3d base, apex;
        double r0 = 0.0, r1 = 0.0, inner = 0.0;
        bool caps = false;
        if (type == "disc") {
            check_object(o, ptr, "a disc",
                         {"type", "name", "center", "normal", "radius", "inner_radius", "material", "transform", "comment"});
            base = vec3(require(o, "center", ptr, "a disc", "an array of 3 numbers"), sub(ptr, "center"));
            Vec3d normal{0, 1, 0};
            if (const Json* n = member(o, "normal")) normal = direction(*n, sub(ptr, "normal"));
            apex = base + normal;
            r0 = r1 = number(require(o, "radius", ptr, "a disc", "a number > 0"), sub(ptr, "radius"), kPositive);
            if (const Json* in = member(o, "inner_radius")) {
                inner = number(*in, sub(ptr, "inner_radius"), kNonNegative);
                if (!(inner < r0)) fail(sub(ptr, "inner_radius"), "inner_radius ({}) must be less than radius ({})", inner, r0);
            }
        } else {
            const bool cone = type == "cone";
            if (cone)
                check_object(o, ptr, "a cone",
                             {"type", "name", "base", "base_radius", "apex", "apex_radius", "open", "material", "transform", "comment"});
            else
                check_object(o, ptr, "a cylinder", {"type", "name", "base", "apex", "radius", "open", "material", "transform", "comment"});
            const char* what = cone ? "a cone" : "a cylinder";
            kind = cone ? QuadricKind::Cone : QuadricKind::Cylinder;
            base = vec3(require(o, "base", ptr, what, "an array of 3 numbers"), sub(ptr, "base"));
            apex = vec3(require(o, "apex", ptr, what, "an array of 3 numbers"), sub(ptr, "apex"));
            const double height = length(apex - base);
            if (!(height > 0.0) || !std::isfinite(height))
                fail(sub(ptr, "apex"), "apex is the base point: the {} has no length", type);
            if (cone) {
                r0 = number(require(o, "base_radius", ptr, what, "a number >= 0"), sub(ptr, "base_radius"), kNonNegative);
                r1 = number(require(o, "apex_radius", ptr, what, "a number >= 0"), sub(ptr, "apex_radius"), kNonNegative);
                if (!(r0 > 0.0 || r1 > 0.0))
                    fail(sub(ptr, "apex_radius"), "base_radius and apex_radius are both 0: the cone has no surface");
            } else {
                r0 = r1 = number(require(o, "radius", ptr, what, "a number > 0"), sub(ptr, "radius"), kPositive);
            }
            caps = true;
            if (const Json* op = member(o, "open")) caps = !boolean(*op, sub(ptr, "open"));
        }
        const uint32_t material = material_ref(o, ptr);
        Mat4d xf;
        if (const Json* t = member(o, "transform")) xf = transform(*t, sub(ptr, "transform"));
        Quadric q = make_quadric(kind, base, apex, r0, r1, caps, xf);
        q.inner_radius = inner;
        q.material = material;
        q.name = name;
        const Bounds3d b = quadric_bounds(q);
        const double limit = double(std::numeric_limits<float>::max());
        if (!(max_abs(b.lo) <= limit && max_abs(b.hi) <= limit))
            fail(ptr, "the {} reaches beyond the float range (|coordinate| > {})", type, limit);
        m_scene.quadrics.push_back(std::move(q));
    }

    void read_plane(const Json& o, const std::string& ptr, const std::string& name) {
        check_object(o, ptr, "a plane",
                     {"type", "name", "point", "normal", "u_axis", "size", "material", "transform", "comment"});
        Vec3d point(0.0), normal{0, 1, 0};
        if (const Json* p = member(o, "point")) point = vec3(*p, sub(ptr, "point"));
        if (const Json* n = member(o, "normal")) normal = direction(*n, sub(ptr, "normal"));
        Vec3d u = default_u_axis(normal);
        if (const Json* ua = member(o, "u_axis")) {
            const Vec3d given = direction(*ua, sub(ptr, "u_axis"));
            u = normalize(given - normal * dot(normal, given));
            if (!(length(u) > 0.5) || std::fabs(dot(given, normal)) > 0.9999)
                fail(sub(ptr, "u_axis"), "u_axis is parallel to the normal");
        }
        const uint32_t material = material_ref(o, ptr);
        std::optional<Mat4d> xf;
        if (const Json* t = member(o, "transform")) xf = transform(*t, sub(ptr, "transform"));
        if (const Json* size = member(o, "size")) {
            // Finite: a rectangle mesh (inside the accelerators).
            const Vec3d wh = [&] {
                const std::string sp = sub(ptr, "size");
                if (!size->is_array() || size->size() != 2) expected(*size, sp, "an array of 2 numbers > 0 (width, height)");
                return Vec3d(number((*size)[0], sub(sp, size_t(0)), kPositive),
                             number((*size)[1], sub(sp, size_t(1)), kPositive), 0.0);
            }();
            Mesh mesh = make_rectangle_mesh(point, normal, u, wh.x, wh.y);
            add_mesh(std::move(mesh), name, material, xf.value_or(Mat4d::identity()), ptr);
            return;
        }
        // Infinite: kept outside the accelerators; a transform moves its point and axes.
        Plane pl;
        pl.name = name;
        pl.material = material;
        pl.point = point;
        pl.normal = normal;
        pl.u_axis = u;
        if (xf) {
            pl.point = xf->apply_point(point);
            pl.normal = normalize(xf->inverse_affine().transposed().apply_vector(normal));
            const Vec3d tu = xf->apply_vector(u);
            pl.u_axis = normalize(tu - pl.normal * dot(pl.normal, tu));
            if (!(length(pl.u_axis) > 0.5)) pl.u_axis = default_u_axis(pl.normal);
        }
        m_scene.planes.push_back(std::move(pl));
    }

    void read_box(const Json& o, const std::string& ptr, const std::string& name) {
        check_object(o, ptr, "a box", {"type", "name", "min", "max", "material", "transform", "comment"});
        const Vec3d lo = vec3(require(o, "min", ptr, "a box", "an array of 3 numbers"), sub(ptr, "min"));
        const Vec3d hi = vec3(require(o, "max", ptr, "a box", "an array of 3 numbers"), sub(ptr, "max"));
        for (int k = 0; k < 3; ++k)
            if (!(hi[k] > lo[k]))
                fail(sub(sub(ptr, "max"), size_t(k)), "max ({}) must be greater than min ({}) on every axis", hi[k], lo[k]);
        const uint32_t material = material_ref(o, ptr);
        Mat4d xf;
        if (const Json* t = member(o, "transform")) xf = transform(*t, sub(ptr, "transform"));
        add_mesh(make_box_mesh(lo, hi), name, material, xf, ptr);
    }

    /// Elements of `count` numbers: nested ([[x, y, z], ...]) or flat ([x, y, z, x, ...]).
    template <typename F>
    size_t read_tuples(const Json& v, const std::string& ptr, int count, const char* what, F&& store) {
        const std::string expect = fmt::format("an array of {}: [[...], ...] or a flat array of numbers", what);
        if (!v.is_array()) expected(v, ptr, expect);
        if (v.empty()) return 0;
        if (v[0].is_array()) {
            for (size_t i = 0; i < v.size(); ++i) {
                const Json& e = v[i];
                const std::string ep = sub(ptr, i);
                if (!e.is_array() || e.size() != size_t(count)) expected(e, ep, fmt::format("an array of {} numbers", count));
                double x[4];
                for (int k = 0; k < count; ++k) x[k] = number(e[size_t(k)], sub(ep, size_t(k)));
                store(i, x);
            }
            return v.size();
        }
        if (v.size() % size_t(count) != 0)
            fail(ptr, "a flat array of {} needs a multiple of {} numbers, got {}", what, count, v.size());
        for (size_t i = 0; i < v.size() / size_t(count); ++i) {
            double x[4];
            for (int k = 0; k < count; ++k) x[k] = number(v[i * size_t(count) + size_t(k)], sub(ptr, i * size_t(count) + size_t(k)));
            store(i, x);
        }
        return v.size() / size_t(count);
    }

    /// Number of tuples `v` holds (nested or flat), for the memory check before reading.
    static size_t tuple_count(const Json& v, size_t count) {
        if (!v.is_array() || v.empty()) return 0;
        return v[0].is_array() ? v.size() : v.size() / count;
    }

    void read_mesh(const Json& o, const std::string& ptr, const std::string& name) {
        check_object(o, ptr, "a mesh",
                     {"type", "name", "positions", "indices", "normals", "uvs", "colors", "material", "transform", "comment"});
        const Json& pos = require(o, "positions", ptr, "a mesh", "an array of [x, y, z] positions");
        const std::string pp = sub(ptr, "positions");
        const Json* idx = member(o, "indices");
        // Memory first: a file may declare millions of vertices.
        const size_t nv_est = tuple_count(pos, 3);
        const size_t ni_est = idx != nullptr && idx->is_array() ? idx->size() * (!idx->empty() && (*idx)[0].is_array() ? 3 : 1) : nv_est;
        reserve(mesh_bytes(nv_est, ni_est, sizeof(Vec3f) * 2 + sizeof(Vec2f) + sizeof(Vec4f)), ptr);

        Mesh mesh;
        mesh.positions.resize(nv_est);
        const size_t nv = read_tuples(pos, pp, 3, "positions", [&](size_t i, const double* x) {
            mesh.positions[i] = {float(x[0]), float(x[1]), float(x[2])};
            if (!is_finite(mesh.positions[i])) fail(sub(pp, i), "position out of the float range");
        });
        mesh.positions.resize(nv);
        if (nv == 0) fail(pp, "a mesh needs at least 3 positions");
        if (nv > size_t(UINT32_MAX)) fail(pp, "too many positions");

        // Indices: 3 per triangle; without them the positions are a triangle list.
        if (idx != nullptr) {
            const std::string ip = sub(ptr, "indices");
            if (!idx->is_array()) expected(*idx, ip, "an array of vertex indices (3 per triangle)");
            auto index = [&](const Json& e, const std::string& ep) {
                const double d = e.is_number() ? e.get<double>() : -1.0;
                if (!e.is_number() || d != std::floor(d) || !(d >= 0) || !(d < double(nv)))
                    expected(e, ep, fmt::format("a vertex index in [0, {}]", nv - 1));
                return uint32_t(d);
            };
            if (!idx->empty() && (*idx)[0].is_array()) {
                for (size_t t = 0; t < idx->size(); ++t) {
                    const Json& tri = (*idx)[t];
                    const std::string tp = sub(ip, t);
                    if (!tri.is_array() || tri.size() != 3) expected(tri, tp, "an array of 3 vertex indices");
                    for (size_t k = 0; k < 3; ++k) mesh.indices.push_back(index(tri[k], sub(tp, k)));
                }
            } else {
                if (idx->size() % 3 != 0) fail(ip, "the index count must be a multiple of 3 (triangles), got {}", idx->size());
                mesh.indices.reserve(idx->size());
                for (size_t k = 0; k < idx->size(); ++k) mesh.indices.push_back(index((*idx)[k], sub(ip, k)));
            }
        } else {
            if (nv % 3 != 0)
                fail(pp, "without \"indices\" the positions are a triangle list: their count must be a multiple of 3, got {}", nv);
            for (uint32_t i = 0; i < uint32_t(nv); ++i) mesh.indices.push_back(i);
        }
        if (mesh.indices.empty()) fail(ptr, "the mesh has no triangles");

        auto check_count = [&](const char* key, size_t n) {
            if (n != nv) fail(sub(ptr, key), "{} {} given for {} positions (one per position)", n, key, nv);
        };
        if (const Json* nr = member(o, "normals")) {
            const std::string np = sub(ptr, "normals");
            mesh.normals.resize(tuple_count(*nr, 3));
            const size_t n = read_tuples(*nr, np, 3, "normals", [&](size_t i, const double* x) {
                if (i >= mesh.normals.size()) return;
                const Vec3d d{x[0], x[1], x[2]};
                const double len = length(d);
                if (!(len > 1e-20) || !std::isfinite(len)) fail(sub(np, i), "a normal of zero length");
                mesh.normals[i] = Vec3f(d / len);
            });
            check_count("normals", n);
        } else {
            mesh.normals = smooth_normals(mesh);
        }
        if (const Json* uv = member(o, "uvs")) {
            mesh.uv0.resize(tuple_count(*uv, 2));
            const size_t n = read_tuples(*uv, sub(ptr, "uvs"), 2, "uvs", [&](size_t i, const double* x) {
                if (i >= mesh.uv0.size()) return;
                mesh.uv0[i] = {float(x[0]), float(x[1])};
                if (!std::isfinite(mesh.uv0[i].x) || !std::isfinite(mesh.uv0[i].y))
                    fail(sub(sub(ptr, "uvs"), i), "uv out of the float range");
            });
            check_count("uvs", n);
        }
        if (const Json* col = member(o, "colors")) {
            // RGB or RGBA per vertex (a flat array: 3 or 4 numbers per position).
            const std::string cp = sub(ptr, "colors");
            int comps = 3;
            if (col->is_array() && !col->empty() && (*col)[0].is_array()) comps = (*col)[0].size() == 4 ? 4 : 3;
            else if (col->is_array() && col->size() == nv * 4) comps = 4;
            mesh.colors.resize(tuple_count(*col, size_t(comps)));
            const size_t n = read_tuples(*col, cp, comps, comps == 4 ? "RGBA colors" : "RGB colors", [&](size_t i, const double* x) {
                if (i >= mesh.colors.size()) return;
                mesh.colors[i] = {float(x[0]), float(x[1]), float(x[2]), comps == 4 ? float(x[3]) : 1.f};
                if (!is_finite(mesh.colors[i].xyz()) || !std::isfinite(mesh.colors[i].w))
                    fail(sub(cp, i), "color out of the float range");
            });
            check_count("colors", n);
        }
        const uint32_t material = material_ref(o, ptr);
        Mat4d xf;
        if (const Json* t = member(o, "transform")) xf = transform(*t, sub(ptr, "transform"));
        add_mesh(std::move(mesh), name, material, xf, ptr, true);
    }

    /// Appends a mesh and the instance placing it (winding flipped under a mirroring transform).
    /// `counted`: its memory was already reserved (inline meshes are checked before reading).
    void add_mesh(Mesh mesh, const std::string& name, uint32_t material, const Mat4d& world, const std::string& ptr,
                  bool counted = false) {
        if (!counted) reserve(mesh_bytes(mesh.positions.size(), mesh.indices.size(), 2 * sizeof(Vec3f) + sizeof(Vec2f)), ptr);
        if (world.det3() < 0) flip_winding(mesh);
        report_mesh_numbers(sanitize_mesh_numbers(mesh), ptr, m_warnings);
        mesh.name = name;
        mesh.material = material;
        Instance inst;
        inst.mesh = uint32_t(m_scene.meshes.size());
        inst.world_from_object = world;
        inst.node_name = name;
        inst.node = -1;
        m_scene.meshes.push_back(std::move(mesh));
        m_scene.instances.push_back(std::move(inst));
    }

    /// Counts `bytes` against ImportOptions::max_memory.
    void reserve(size_t bytes, const std::string& ptr) {
        if (bytes > m_options.max_memory || m_bytes > m_options.max_memory - bytes)
            fail(ptr, "the scene needs more than the memory limit of {} MiB (ImportOptions::max_memory, --max-memory)",
                 m_options.max_memory >> 20);
        m_bytes += bytes;
    }

    // ---- lights -------------------------------------------------------------------------------
    void read_lights(const Json& v) {
        if (!v.is_array()) expected(v, "/lights", "an array of lights");
        std::map<std::string, int> counts;
        for (size_t i = 0; i < v.size(); ++i) {
            const std::string ptr = sub("/lights", i);
            const Json& o = v[i];
            if (!o.is_object()) expected(o, ptr, "an object (a point, spot or directional light)");
            const std::string type =
                choice(require(o, "type", ptr, "a light", "\"point\", \"spot\" or \"directional\""), sub(ptr, "type"),
                       {"point", "spot", "directional"});
            Light l;
            l.name = fmt::format("{} light {}", type, counts[type]++);
            if (type == "point") {
                check_object(o, ptr, "a point light",
                             {"type", "name", "position", "color", "intensity", "attenuation", "range", "comment"});
                l.type = LightType::Point;
            } else if (type == "spot") {
                check_object(o, ptr, "a spot light",
                             {"type", "name", "position", "direction", "look_at", "inner_angle", "outer_angle", "color",
                              "intensity", "attenuation", "range", "comment"});
                l.type = LightType::Spot;
            } else {
                check_object(o, ptr, "a directional light", {"type", "name", "direction", "color", "intensity", "comment"});
                l.type = LightType::Directional;
            }
            if (const Json* n = member(o, "name")) l.name = string(*n, sub(ptr, "name"));
            if (const Json* c = member(o, "color")) l.color = color(*c, sub(ptr, "color"));
            if (const Json* in = member(o, "intensity")) l.intensity = float(number(*in, sub(ptr, "intensity"), kNonNegative));
            if (!std::isfinite(l.intensity)) fail(sub(ptr, "intensity"), "intensity out of the float range");
            if (l.type != LightType::Directional) {
                l.position = vec3(require(o, "position", ptr, "a " + type + " light", "an array of 3 numbers"),
                                  sub(ptr, "position"));
                l.attenuation = Attenuation::InverseSquare;
                if (const Json* a = member(o, "attenuation")) read_attenuation(*a, sub(ptr, "attenuation"), l);
                if (const Json* r = member(o, "range")) l.range = float(number(*r, sub(ptr, "range"), kNonNegative));
            } else {
                l.attenuation = Attenuation::None;
                l.direction = direction(require(o, "direction", ptr, "a directional light", "an array of 3 numbers"),
                                        sub(ptr, "direction"));
            }
            if (l.type == LightType::Spot) {
                const Json* dir = member(o, "direction");
                const Json* look = member(o, "look_at");
                if (dir != nullptr && look != nullptr) fail_key(sub(ptr, "look_at"), "give 'direction' or 'look_at', not both");
                if (dir == nullptr && look == nullptr)
                    fail(ptr, "missing key 'direction' or 'look_at' in a spot light (where it points)");
                if (dir != nullptr) {
                    l.direction = direction(*dir, sub(ptr, "direction"));
                } else {
                    l.direction = normalize(vec3(*look, sub(ptr, "look_at")) - l.position);
                    if (!(length(l.direction) > 0.5)) fail(sub(ptr, "look_at"), "look_at is the light's position: no direction");
                }
                double inner = 0.0, outer = 45.0;
                if (const Json* a = member(o, "outer_angle")) outer = number(*a, sub(ptr, "outer_angle"), Range{0.0, 90.0, true, false});
                if (const Json* a = member(o, "inner_angle")) inner = number(*a, sub(ptr, "inner_angle"), Range{0.0, 90.0});
                if (inner > outer)
                    fail(sub(ptr, "inner_angle"), "inner_angle ({}) must not exceed outer_angle ({})", inner, outer);
                l.inner_cone = float(inner * kDegrees);
                l.outer_cone = float(outer * kDegrees);
            }
            m_scene.lights.push_back(std::move(l));
        }
    }

    void read_attenuation(const Json& a, const std::string& ptr, Light& l) const {
        const char* what = "\"inverse_square\", \"none\" or [c1, c2, c3] (fat = min(1, 1/(c1 + c2 d + c3 d^2)))";
        if (a.is_string()) {
            const std::string s = choice(a, ptr, {"inverse_square", "none"});
            l.attenuation = s == "none" ? Attenuation::None : Attenuation::InverseSquare;
            return;
        }
        if (!a.is_array() || a.size() != 3) expected(a, ptr, what);
        Vec3f c;
        for (int k = 0; k < 3; ++k) c[k] = float(number(a[size_t(k)], sub(ptr, size_t(k)), kNonNegative));
        if (!is_finite(c)) fail(ptr, "attenuation coefficient out of the float range");
        if (!(c.x + c.y + c.z > 0.f)) fail(ptr, "at least one of c1, c2, c3 must be > 0 ([1, 0, 0] = no attenuation)");
        l.attenuation = Attenuation::Classic;
        l.classic_c = c;
    }

    // ---- includes -----------------------------------------------------------------------------
    /// A path from the file, relative to the scene file's folder (".." allowed; absolute too).
    fs::path resolve(const std::string& file, const std::string& ptr, const char* what) const {
        if (file.find('\0') != std::string::npos) fail(ptr, "the file name contains a NUL byte");
        fs::path p(file);
        if (p.is_relative()) p = m_dir / p;
        p = p.lexically_normal();
        std::error_code ec;
        const fs::file_status st = fs::status(p, ec);
        if (ec || !fs::exists(st)) fail(ptr, "{} file '{}' not found (looked for '{}')", what, file, p.string());
        if (!fs::is_regular_file(st)) fail(ptr, "{} file '{}' is not a regular file ('{}')", what, file, p.string());
        return p;
    }

    void read_includes(const Json& v) {
        if (!v.is_array()) expected(v, "/include", "an array of included glTF files");
        for (size_t i = 0; i < v.size(); ++i) read_include(v[i], sub("/include", i));
    }

    void read_include(const Json& o, const std::string& ptr) {
        check_object(o, ptr, "an include",
                     {"file", "transform", "scene", "materials", "lights", "cameras", "animation", "time_offset", "variant",
                      "comment"});
        const std::string fp = sub(ptr, "file");
        const std::string file = string(require(o, "file", ptr, "an include", "a .gltf or .glb file name"), fp);
        const std::string ext = lower_ext(file);
        if (ext != ".gltf" && ext != ".glb")
            fail(fp, "'{}': only glTF files (.gltf, .glb) can be included", file);
        const fs::path path = resolve(file, fp, "included");
        Mat4d xf;
        if (const Json* t = member(o, "transform")) xf = transform(*t, sub(ptr, "transform"));
        ImportOptions sub_options = m_options;
        sub_options.add_default_camera = false;
        sub_options.add_default_light = false;
        sub_options.scene_index = -1;
        if (const Json* s = member(o, "scene")) sub_options.scene_index = integer(*s, sub(ptr, "scene"), 0, INT32_MAX);
        // Its animations: which, and at what time (the render's time plus the offset; glTF key
        // times are not negative, so an earlier moment is the first key's).
        if (const Json* a = member(o, "animation")) sub_options.animation = string(*a, sub(ptr, "animation"));
        // A KHR_materials_variants variant of the included file (the render's --variant is the
        // top file's: a scene file has none, so it does not pass down).
        sub_options.variant.clear();
        if (const Json* v = member(o, "variant")) sub_options.variant = string(*v, sub(ptr, "variant"));
        if (const Json* t = member(o, "time_offset"))
            sub_options.time = std::max(0.0, m_options.time + number(*t, sub(ptr, "time_offset")));
        sub_options.max_memory = m_options.max_memory > m_bytes ? m_options.max_memory - m_bytes : 0;
        bool with_lights = true, with_cameras = true;
        if (const Json* l = member(o, "lights")) with_lights = boolean(*l, sub(ptr, "lights"));
        if (const Json* c = member(o, "cameras")) with_cameras = boolean(*c, sub(ptr, "cameras"));

        Scene inc;
        try {
            inc = import_gltf(path.string(), sub_options);
        } catch (const Error& e) {
            // Keep the location inside the glTF file; say where it was included from.
            std::string message = e.what();
            const std::string prefix = e.location().to_string();
            if (!prefix.empty() && message.rfind(prefix + ": ", 0) == 0) message = message.substr(prefix.size() + 2);
            FileLoc loc = e.location();
            if (loc.file.empty()) loc.file = path.string();
            throw Error(loc, fmt::format("{} (included from {})", message, scene_file::locate(m_doc, fp).to_string()));
        }
        m_bytes += scene_bytes(inc);

        // Material overrides: glTF material name -> scene-file material.
        std::vector<int64_t> override_of(inc.materials.size(), -1);
        if (const Json* mo = member(o, "materials")) {
            const std::string mp = sub(ptr, "materials");
            if (!mo->is_object()) expected(*mo, mp, "an object mapping glTF material names to scene-file material names");
            std::vector<std::string> gltf_names;
            for (const Material& m : inc.materials) gltf_names.push_back(m.name);
            for (const auto& [gname, target] : mo->items()) {
                const std::string ep = sub(mp, gname);
                const uint32_t to = material_named(string(target, ep), ep);
                bool found = false;
                for (size_t k = 0; k < inc.materials.size(); ++k)
                    if (inc.materials[k].name == gname) override_of[k] = to, found = true;
                if (!found)
                    fail_key(ep, "the included file '{}' has no material named '{}' (to be replaced by '{}'){}", file, gname,
                             target.get<std::string>(), suggestion(gname, gltf_names));
            }
        }

        // Append with indices remapped; the include transform premultiplies every placement.
        const auto mesh_offset = uint32_t(m_scene.meshes.size());
        const auto mat_offset = uint32_t(m_scene.materials.size());
        const auto tex_offset = int32_t(m_scene.textures.size());
        const bool mirrors = xf.det3() < 0;
        for (Mesh& m : inc.meshes) {
            m.material = override_of[m.material] >= 0 ? uint32_t(override_of[m.material]) : m.material + mat_offset;
            if (mirrors) flip_winding(m);
            m_scene.meshes.push_back(std::move(m));
        }
        for (Instance& in : inc.instances) {
            in.mesh += mesh_offset;
            in.world_from_object = xf * in.world_from_object;
            m_scene.instances.push_back(std::move(in));
        }
        for (Material& m : inc.materials) {
            for (TextureRef* r : m.texture_slots()) shift(*r, tex_offset);
            m_scene.materials.push_back(std::move(m));
        }
        for (Texture& t : inc.textures) m_scene.textures.push_back(std::move(t));
        if (with_lights)
            for (Light& l : inc.lights) {
                l.position = xf.apply_point(l.position);
                const Vec3d d = normalize(xf.apply_vector(l.direction));
                if (length(d) > 0.5) l.direction = d;
                m_scene.lights.push_back(std::move(l));
            }
        if (with_cameras)
            for (Camera& c : inc.cameras) {
                c.world_from_camera = xf * c.world_from_camera;
                m_scene.cameras.push_back(std::move(c));
            }
        for (const ExtensionUse& e : inc.extensions) {
            auto it = std::find_if(m_scene.extensions.begin(), m_scene.extensions.end(),
                                   [&](const ExtensionUse& x) { return x.name == e.name; });
            if (it == m_scene.extensions.end()) m_scene.extensions.push_back(e);
            else it->required = it->required || e.required;
        }
        for (const std::string& w : inc.warnings) m_scene.warn(fmt::format("{}: {}", file, w));
        for (AnimationInfo& a : inc.animations) {
            a.name = fmt::format("{}: {}", file, a.name);
            m_scene.animations.push_back(std::move(a));
        }
        for (SkinInfo& k : inc.skins) m_scene.skins.push_back(std::move(k));
        for (MorphInfo& m : inc.morphs) m_scene.morphs.push_back(std::move(m));
        m_scene.time = m_options.time;
    }

    // ---- environment --------------------------------------------------------------------------
    /// "environment": a file or bundled name, or {"file", "rotation", "exposure", "visible"}.
    void read_environment(const Json& v) {
        const std::string p = "/environment";
        Environment env;
        std::string file;
        if (v.is_string()) {
            file = string(v, p);
        } else {
            check_object(v, p, "the environment", {"file", "rotation", "exposure", "visible", "comment"});
            const Json* f = member(v, "file");
            if (!f) fail(p, "the environment needs a \"file\" (a lat-long image or a bundled name)");
            file = string(*f, sub(p, "file"));
            if (const Json* x = member(v, "rotation")) env.rotation_deg = float(number(*x, sub(p, "rotation"), Range{-3600.0, 3600.0}));
            if (const Json* x = member(v, "exposure")) env.exposure_stops = float(number(*x, sub(p, "exposure"), Range{-64.0, 64.0}));
            if (const Json* x = member(v, "visible")) env.visible = boolean(*x, sub(p, "visible"));
        }
        if (!m_options.environment.empty() || m_options.no_environment) return;  // replaced by the caller's
        // A path relative to the scene file, else a bundled name (resolve_environment_name).
        fs::path path(file);
        if (path.is_relative()) path = m_dir / path;
        std::error_code ec;
        const std::string where = fs::exists(path, ec) ? path.lexically_normal().string() : file;
        std::vector<std::string> warnings;
        std::string resolved;
        try {
            resolved = resolve_environment_name(where);
            env.image = std::make_shared<EnvironmentImage>(load_environment_image(resolved, m_options.max_memory, warnings));
        } catch (const Error& e) {
            fail(v.is_string() ? p : sub(p, "file"), "{}", e.what());
        }
        for (const std::string& w : warnings)
            if (is_bundled_environment(resolved)) log_info("{}", w);
            else m_scene.warn(w);
        m_scene.environment = std::move(env);
    }

    // ---- render settings ----------------------------------------------------------------------
    void read_render(const Json& v) {
        check_object(v, "/render", "the render settings",
                     {"width", "height", "aa", "aa_threshold", "aa_depth", "spp", "max_depth", "min_weight",
                      "background", "exposure", "fresnel", "output", "view", "display", "camera", "comment"});
        SceneRenderSettings& s = m_scene.settings;
        const std::string p = "/render";
        if (const Json* x = member(v, "width")) s.width = integer(*x, sub(p, "width"), 1, 32768);
        if (const Json* x = member(v, "height")) s.height = integer(*x, sub(p, "height"), 1, 32768);
        if (const Json* x = member(v, "aa")) s.aa = choice(*x, sub(p, "aa"), {"center", "corners", "adaptive", "stratified"});
        if (const Json* x = member(v, "aa_threshold")) s.aa_threshold = float(number(*x, sub(p, "aa_threshold")));
        if (const Json* x = member(v, "aa_depth")) s.aa_depth = integer(*x, sub(p, "aa_depth"), 0, 8);
        if (const Json* x = member(v, "spp")) {
            const int spp = integer(*x, sub(p, "spp"), 1, 4096);
            const int k = int(std::lround(std::sqrt(double(spp))));
            if (k * k != spp) fail(sub(p, "spp"), "expected a square number of samples (k*k: 1, 4, 9, 16, ...), got {}", spp);
            s.spp = spp;
        }
        if (const Json* x = member(v, "max_depth")) s.max_depth = integer(*x, sub(p, "max_depth"), 0, 64);
        if (const Json* x = member(v, "min_weight")) s.min_weight = float(number(*x, sub(p, "min_weight"), Range{0.0, 1.0}));
        if (const Json* x = member(v, "background")) s.background = color(*x, sub(p, "background"));
        if (const Json* x = member(v, "exposure")) s.exposure = float(number(*x, sub(p, "exposure"), Range{-64.0, 64.0}));
        if (const Json* x = member(v, "fresnel")) s.fresnel = boolean(*x, sub(p, "fresnel"));
        if (const Json* x = member(v, "output")) s.output = string(*x, sub(p, "output"));
        if (const Json* x = member(v, "view")) s.view = string(*x, sub(p, "view"));
        if (const Json* x = member(v, "display")) s.display = string(*x, sub(p, "display"));
        if (const Json* x = member(v, "camera")) s.camera = integer(*x, sub(p, "camera"), 0, INT32_MAX);
    }

    const JsonDocument& m_doc;
    const ImportOptions m_options;
    fs::path m_dir;                                   ///< folder of the scene file (absolute)
    size_t m_bytes = 0;                               ///< memory estimate so far
    Scene m_scene;
    WarningLog m_warnings;
    std::map<std::string, uint32_t, std::less<>> m_material_index; ///< file material name -> Scene material
    std::vector<std::string> m_material_names;        ///< in file order (suggestions)
    std::map<std::string, NamedTexture> m_textures;
    std::vector<std::string> m_texture_names;
    int m_default_material = -1;
};

std::string read_text(const std::string& path, size_t max_memory) {
    std::error_code ec;
    if (fs::is_directory(path, ec)) throw Error(FileLoc{path, "", 0, 0}, "is a directory, not a scene file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(FileLoc{path, "", 0, 0}, fmt::format("cannot open file: {}", std::strerror(errno)));
    in.seekg(0, std::ios::end);
    const std::streamoff size = in.tellg();
    in.seekg(0, std::ios::beg);
    if (size < 0) throw Error(FileLoc{path, "", 0, 0}, "cannot determine the file size");
    if (uint64_t(size) > max_memory / kJsonBytesPerByte)
        throw Error(FileLoc{path, "", 0, 0},
                    fmt::format("scene file of {} bytes is too large for the memory limit of {} MiB (parsing takes up "
                                "to {}x the file size; put large meshes in glTF files and include them)",
                                size, max_memory >> 20, kJsonBytesPerByte));
    std::string text(static_cast<size_t>(size), '\0');
    if (size > 0 && !in.read(text.data(), size)) throw Error(FileLoc{path, "", 0, 0}, "read error");
    return text;
}

/// import_scene_file_text on text the document takes over (a file's text is not copied: 81 MB
/// of a million spheres cost about 0.2 s to copy, most of it the new pages). The callers have
/// checked its size against the memory limit (read_text, import_scene_file_text).
Scene import_owned_text(std::string text, const std::string& path, const ImportOptions& options) {
    if (text.find_first_not_of(" \t\r\n") == std::string::npos)
        throw Error(FileLoc{path, "", 0, 0}, "empty scene file (expected a JSON object)");
    const JsonDocument doc = scene_file::parse_json_document(std::move(text), path);
    return SceneFileReader(doc, options).run();
}

}  // namespace

Scene import_scene_file_text(std::string_view text, const std::string& path, const ImportOptions& options) {
    if (text.size() > options.max_memory / kJsonBytesPerByte)  // before the copy
        throw Error(FileLoc{path, "", 0, 0},
                    fmt::format("scene file of {} bytes is too large for the memory limit of {} MiB", text.size(),
                                options.max_memory >> 20));
    return import_owned_text(std::string(text), path, options);
}

Scene import_scene_file(const std::string& path, const ImportOptions& options) {
    return import_owned_text(read_text(path, options.max_memory), path, options);
}

}  // namespace whitted
