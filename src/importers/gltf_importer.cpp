// glTF 2.0 -> Scene.
//
// Pipeline: read the file and pre-check its container (empty, BOM, GLB header and chunks) ->
// tinygltf parses JSON, buffers and data URIs (image bytes are only captured, never decoded
// here) -> validate_gltf() checks every object -> extensions are classified -> the chosen scene
// is traversed into instances, cameras and lights -> the memory estimate is checked -> geometry
// is decoded (shared by every instance, one mirrored copy where a mirroring transform needs it)
// -> textures are decoded -> a default camera and light are added when the file has none.
// Every failure is a whitted::Error naming the file and, where one applies, a JSON pointer.

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <numbers>
#include <numeric>
#include <optional>
#include <span>
#include <string_view>
#include <tuple>
#include <unordered_map>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <tbb/parallel_for.h>
#include <tiny_gltf.h>

#include "importers/file_bytes.h"
#include "importers/gltf_accessor.h"
#include "importers/gltf_animation.h"
#include "importers/gltf_variants.h"
#include "importers/gltf_extensions.h"
#include "importers/gltf_json.h"
#include "importers/gltf_compressed.h"
#include "importers/gltf_draco.h"
#include "importers/gltf_meshopt.h"
#include "importers/gltf_validation.h"
#include "importers/image_decode.h"
#include "importers/mesh_normals.h"
#include "importers/mesh_numbers.h"
#include "importers/scene_defaults.h"
#include "importers/scene_loader.h"
#include "importers/warning_log.h"
#include "importers/located_error.h"
#include "core/error.h"
#include "core/log.h"
#include "shading/texture_sampling.h"

namespace whitted {

namespace {

using namespace gltf;

constexpr size_t kMaxJsonDepth = 64;  ///< array/object nesting (docs/fuzzing.md)
constexpr double kNoLimit = std::numeric_limits<double>::infinity();  ///< an unbounded factor

// ---------------------------------------------------------------------------------------------
// Reading the file

FileBytes read_file(const std::string& path, size_t max_memory) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) throw Error(file_loc(path), "is a directory, not a glTF file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(file_loc(path), fmt::format("cannot open file: {}", std::strerror(errno)));
    in.seekg(0, std::ios::end);
    const std::streamoff size = in.tellg();
    in.seekg(0, std::ios::beg);
    if (size < 0) throw Error(file_loc(path), "cannot determine the file size");
    // tinygltf takes 32-bit lengths.
    if (uint64_t(size) >= (uint64_t(1) << 32)) throw Error(file_loc(path), "file is 4 GiB or larger: not supported");
    if (uint64_t(size) > max_memory)
        throw Error(file_loc(path),
                    fmt::format("file of {} bytes exceeds the memory limit of {} bytes", size, max_memory));
    FileBytes bytes(static_cast<size_t>(size));
    if (size > 0 && !in.read(reinterpret_cast<char*>(bytes.data()), size)) throw Error(file_loc(path), "read error");
    return bytes;
}

uint32_t load_u32(const uint8_t* p) {
    uint32_t v;
    std::memcpy(&v, p, 4);
    return v;
}

/// GLB container checks (glTF 2.0 spec 4.4) with messages that say what is wrong; tinygltf's
/// own checks only say "Invalid glTF binary".
void check_glb_container(const std::string& path, std::span<const uint8_t> b, Scene& scene) {
    if (b.size() < 12)
        throw Error(file_loc(path), fmt::format("truncated GLB: {} bytes, the header needs 12", b.size()));
    if (std::memcmp(b.data(), "glTF", 4) != 0)
        throw Error(file_loc(path), fmt::format("invalid GLB magic 0x{:08x} (expected 'glTF')", load_u32(b.data())));
    const uint32_t version = load_u32(b.data() + 4);
    if (version != 2)
        throw Error(file_loc(path), fmt::format("unsupported GLB container version {} (expected 2)", version));
    const uint64_t length = load_u32(b.data() + 8);
    if (length > b.size())
        throw Error(file_loc(path),
                    fmt::format("truncated GLB: the header declares {} bytes, the file has {}", length, b.size()));
    if (length < b.size())
        scene.warn(
            fmt::format("GLB header declares {} bytes, the file has {}: trailing bytes ignored", length, b.size()));
    if (length < 20) throw Error(file_loc(path), "truncated GLB: no JSON chunk");
    const uint64_t json_length = load_u32(b.data() + 12);
    if (load_u32(b.data() + 16) != 0x4E4F534Au) throw Error(file_loc(path), "the first GLB chunk is not JSON");
    if (20 + json_length > length)
        throw Error(file_loc(path),
                    fmt::format("truncated GLB: JSON chunk of {} bytes does not fit the {} bytes declared", json_length,
                                length));
    const uint64_t bin_start = 20 + json_length;
    if (bin_start < length) {
        if (bin_start + 8 > length) throw Error(file_loc(path), "truncated GLB: incomplete BIN chunk header");
        const uint64_t bin_length = load_u32(b.data() + bin_start);
        if (bin_start + 8 + bin_length > length)
            throw Error(file_loc(path),
                        fmt::format("truncated GLB: BIN chunk of {} bytes does not fit the {} bytes declared",
                                    bin_length, length));
    }
}

// Image bytes are captured by this loader and decoded only after validation: tinygltf hands an
// image's bufferView bytes to the loader before anything has checked that range.
struct ImageCapture {
    bool seen = false;              ///< tinygltf found the bytes (file, data URI or bufferView)
    bool from_buffer_view = false;  ///< bytes are in a bufferView (read after validation)
    std::vector<uint8_t> encoded;   ///< PNG/JPEG bytes of uri / data-URI images
};

struct LoaderState {
    std::vector<ImageCapture> images;
    bool keep_bytes = true;  ///< false with ImportOptions::load_textures == false
    size_t max_memory = 0;   ///< ImportOptions::max_memory, for the image header check
    std::string refused;     ///< "/images/<i>: <reason>" of the first image refused by its header
};

/// tinygltf's image-loader hook: keeps the encoded bytes of uri / data-URI images after checking
/// the dimensions their header declares (so a small file cannot claim a 100000 x 100000 image).
bool capture_image(tinygltf::Image* image, const int index, std::string* err, std::string*, int, int,
                   const unsigned char* bytes, int size, void* user) {
    auto* state = static_cast<LoaderState*>(user);
    if (index < 0) return false;
    if (size_t(index) >= state->images.size()) state->images.resize(size_t(index) + 1);
    ImageCapture& c = state->images[size_t(index)];
    c.seen = true;
    if (image->bufferView >= 0) {
        c.from_buffer_view = true;  // `bytes` may point outside the buffer: do not touch (checked at decode)
        return true;
    }
    if (!state->keep_bytes || bytes == nullptr || size <= 0) return true;
    // Formats the header parser does not know fail later, at decoding, with their own message.
    int w = 0, h = 0;
    if (image_size_from_header(bytes, size_t(size), w, h)) {
        if (const std::string why = check_image_size(w, h, state->max_memory); !why.empty()) {
            if (state->refused.empty()) state->refused = fmt::format("/images/{}: {}", index, why);
            if (err != nullptr) *err += why + "\n";
            return false;
        }
    }
    c.encoded.assign(bytes, bytes + size);
    return true;
}

/// Where tinygltf may read external resources (buffers and images), enforced in its file-system
/// callbacks since it reads them while parsing: relative URIs resolve against the glTF file's
/// folder (never the working directory); leaving that folder ("../") needs
/// ImportOptions::allow_outside_uris; absolute paths and URIs with a scheme (file://, http://)
/// are always refused. The first refusal becomes the import error.
struct UriPolicy {
    std::string base;            ///< absolute, normalized folder of the glTF file (tinygltf's base_dir)
    bool allow_outside = false;  ///< ImportOptions::allow_outside_uris
    size_t max_bytes = 0;        ///< largest resource read (ImportOptions::max_memory)
    std::string refused;         ///< first refusal, one line
};

/// The file a tinygltf lookup ("<base>/<uri>") may read under the policy; nullopt when refused
/// (the reason is recorded) or when tinygltf tries its working-directory fallback ("./<uri>").
std::optional<std::filesystem::path> resolve_uri(const std::string& lookup, UriPolicy& policy) {
    namespace fs = std::filesystem;
    const std::string prefix = !policy.base.empty() && policy.base.back() == '/' ? policy.base : policy.base + "/";
    if (lookup.compare(0, prefix.size(), prefix) != 0) return std::nullopt;
    const std::string uri = lookup.substr(prefix.size());
    auto refuse = [&](const std::string& why) -> std::optional<fs::path> {
        std::string shown = uri;  // control bytes (a decoded %00) must not reach the terminal
        for (char& c : shown)
            if ((unsigned char)c < 0x20 || c == 0x7f) c = '?';
        if (policy.refused.empty()) policy.refused = fmt::format("external URI '{}' refused: {}", shown, why);
        return std::nullopt;
    };
    // A scheme ("file:", "http:"): RFC 3986 3.1, ALPHA *( ALPHA / DIGIT / "+" / "-" / "." ) ":".
    size_t k = 0;
    while (k < uri.size() && (std::isalnum((unsigned char)uri[k]) || uri[k] == '+' || uri[k] == '-' || uri[k] == '.'))
        ++k;
    const bool has_scheme = k > 0 && k < uri.size() && uri[k] == ':' && std::isalpha((unsigned char)uri[0]);
    // Empty URIs and data: URIs tinygltf could not decode end in its own, clearer errors.
    if (uri.empty() || (has_scheme && uri.compare(0, 5, "data:") == 0)) return std::nullopt;
    if (has_scheme)
        return refuse(fmt::format("'{}' URIs are not read (only paths relative to the glTF file and data: URIs)",
                                  uri.substr(0, k + 1)));
    // tinygltf has already percent-decoded the URI ("%2e%2e/" arrives as "../"; "%00" as a NUL).
    const std::string& rel = uri;
    if (rel.find('\0') != std::string::npos) return refuse("it contains a NUL byte");
    if (rel[0] == '/') return refuse("absolute paths are not read (use a path relative to the glTF file)");
    const fs::path base(policy.base);
    const fs::path target = (base / rel).lexically_normal();
    const fs::path inside = target.lexically_relative(base);
    const bool outside = inside.empty() || *inside.begin() == "..";
    if (outside && !policy.allow_outside)
        return refuse("it leaves the folder of the glTF file (allow with --allow-outside-uris)");
    return target;
}

/// FsCallbacks::FileExists under the policy: regular files only (no devices, FIFOs, folders).
bool policy_file_exists(const std::string& lookup, void* user) {
    auto& policy = *static_cast<UriPolicy*>(user);
    if (meshopt_fallback_size(lookup)) return true;
    const std::optional<std::filesystem::path> file = resolve_uri(lookup, policy);
    if (!file) return false;
    std::error_code ec;
    const std::filesystem::file_status st = std::filesystem::status(*file, ec);
    if (ec || !std::filesystem::exists(st)) return false;
    if (!std::filesystem::is_regular_file(st)) {
        if (policy.refused.empty())
            policy.refused = fmt::format("external URI '{}' is not a regular file", file->string());
        return false;
    }
    return true;
}

/// FsCallbacks::ReadWholeFile under the policy, refusing files larger than the memory limit.
bool policy_read_file(std::vector<unsigned char>* out, std::string* err, const std::string& lookup, void* user) {
    auto& policy = *static_cast<UriPolicy*>(user);
    if (const std::optional<size_t> fallback = meshopt_fallback_size(lookup)) {  // zeros, decoded into later
        if (*fallback > policy.max_bytes) {
            if (policy.refused.empty())
                policy.refused = fmt::format("an EXT_meshopt_compression buffer of {} bytes exceeds the memory limit "
                                             "of {} bytes", *fallback, policy.max_bytes);
            if (err) *err += "over the memory limit";
            return false;
        }
        out->assign(*fallback, 0);
        return true;
    }
    const std::optional<std::filesystem::path> file = resolve_uri(lookup, policy);
    if (!file) {
        if (err) *err += "refused by the URI policy";
        return false;
    }
    std::error_code ec;
    const uintmax_t size = std::filesystem::file_size(*file, ec);
    if (ec || size > policy.max_bytes) {
        if (!ec && policy.refused.empty())
            policy.refused = fmt::format("external file '{}' of {} bytes exceeds the memory limit of {} bytes",
                                         file->string(), size, policy.max_bytes);
        if (err) *err += ec ? ec.message() : "over the memory limit";
        return false;
    }
    std::ifstream in(*file, std::ios::binary);
    out->resize(size_t(size));
    if (!in || (size > 0 && !in.read(reinterpret_cast<char*>(out->data()), std::streamsize(size)))) {
        if (err) *err += "read error";
        return false;
    }
    return true;
}

bool refuse_write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
    if (err) *err += "whitted never writes through tinygltf";
    return false;
}

/// What one pass over the JSON text finds before tinygltf parses it.
struct JsonOutline {
    size_t depth = 0;  ///< deepest array/object nesting (the scan stops once it passes the limit)
    // Objects in the top-level arrays tinygltf fills one element at a time.
    size_t accessors = 0, buffer_views = 0, meshes = 0, nodes = 0, materials = 0;
};

/// Scans the JSON text for its nesting depth, stopping once `limit` is passed (tinygltf converts
/// extras and extensions recursively, so a file of 100000 '[' would overflow the stack), and
/// counts the objects of the large top-level arrays so the model's vectors can be reserved.
JsonOutline json_outline(const char* p, size_t n, size_t limit) {
    JsonOutline o;
    size_t depth = 0;
    bool in_string = false;
    size_t string_start = 0;
    std::string_view last_key;  // the last string closed at depth 1: a key of the root object
    size_t* counter = nullptr;  // the count of the top-level array being scanned
    auto counter_for = [&o](std::string_view key) -> size_t* {
        if (key == "accessors") return &o.accessors;
        if (key == "bufferViews") return &o.buffer_views;
        if (key == "meshes") return &o.meshes;
        if (key == "nodes") return &o.nodes;
        if (key == "materials") return &o.materials;
        return nullptr;
    };
    for (size_t i = 0; i < n && o.depth <= limit; ++i) {
        const char c = p[i];
        if (in_string) {
            if (c == '\\') {
                ++i;  // skip the escaped character
            } else if (c == '"') {
                in_string = false;
                if (depth == 1) last_key = std::string_view(p + string_start, i - string_start);
            }
        } else if (c == '"') {
            in_string = true;
            string_start = i + 1;
        } else if (c == '[' || c == '{') {
            if (depth == 2 && c == '{' && counter != nullptr) ++*counter;
            if (depth == 1 && c == '[') counter = counter_for(last_key);
            o.depth = std::max(o.depth, ++depth);
        } else if ((c == ']' || c == '}') && depth > 0) {
            if (--depth == 1) counter = nullptr;
        }
    }
    return o;
}

/// Room for `n` elements, when they fit the memory limit: tinygltf appends them one at a time
/// (and only clears, never shrinks, the vectors first). A hint: without it the vector grows.
template <typename T>
void reserve_for(std::vector<T>& v, size_t n, size_t max_memory) {
    if (n == 0 || n > max_memory / sizeof(T)) return;
    try {
        v.reserve(n);
    } catch (const std::bad_alloc&) {
    }
}

/// Shortens the payload of every data URI in a message ("data:...;base64,AAAA... (123456 chars)"):
/// tinygltf quotes whole URIs, which can be megabytes.
std::string shorten_data_uris(const std::string& s) {
    std::string out;
    size_t pos = 0;
    while (true) {
        const size_t data = s.find("data:", pos);
        const size_t comma = data == std::string::npos ? std::string::npos : s.find(',', data);
        if (comma == std::string::npos) break;
        size_t end = comma + 1;
        while (end < s.size() && s[end] != ' ' && s[end] != '\n' && s[end] != '\'' && s[end] != '"') ++end;
        out.append(s, pos, comma + 1 - pos);
        const size_t payload = end - comma - 1;
        if (payload > 24)
            out += s.substr(comma + 1, 16) + fmt::format("... ({} chars)", payload);
        else
            out.append(s, comma + 1, payload);
        pos = end;
    }
    return out + s.substr(pos);
}

/// tinygltf's multi-line messages as one line.
std::string one_line(std::string s) {
    while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
    std::string out;
    for (char c : shorten_data_uris(s)) {
        if (c == '\n')
            out += "; ";
        else if (c != '\r')
            out += c;
    }
    return out;
}

// ---------------------------------------------------------------------------------------------
// Small helpers

std::string node_label(const tinygltf::Model& model, int node) {
    const std::string& n = model.nodes[size_t(node)].name;
    return n.empty() ? fmt::format("node {}", node) : n;
}

// ---------------------------------------------------------------------------------------------
// The importer

/// Which Scene mesh a (glTF mesh, primitive, mirrored) triple became.
struct MeshKey {
    int mesh, primitive;
    bool mirrored;
    int node = -1;  ///< the node whose pose deforms the mesh (skin, morph targets); -1: not deformed
    bool operator<(const MeshKey& o) const {
        return std::tie(mesh, primitive, mirrored, node) < std::tie(o.mesh, o.primitive, o.mirrored, o.node);
    }
};

class GltfImporter {
public:
    GltfImporter(const std::string& path, const ImportOptions& options) : m_path(path), m_options(options) {}

    /// Imports the glTF (JSON or GLB) held in `bytes`.
    Scene run(std::span<const uint8_t> bytes) {
        m_scene.source = m_path;
        load_model(bytes);
        validate_gltf(m_model, m_path, m_options.max_memory, m_scene);
        check_images_present();
        classify_extensions();
        choose_variant();
        pose();
        convert_materials();
        traverse_scene();
        check_memory();
        build_meshes();
        decode_textures();
        add_defaults();
        describe_animation(m_model, m_animations, m_scene);
        m_warnings.flush_to(m_scene);
        return std::move(m_scene);
    }

    /// `scene` (what run() returned, as the last call left it) posed at `time` in place, as run()
    /// would have built it at that time: instance transforms, deforming meshes' vertices (positions
    /// in their own allocation), the file's cameras and lights, animated material factors. Nothing
    /// when the node graph's structure changed (an instance now needs another mesh: a transform
    /// turned mirroring); the caller imports the file again.
    std::optional<SceneUpdate> repose(Scene& scene, double time) {
        m_options.time = time;
        WarningLog log;
        std::swap(log, m_warnings);
        m_pose = pose_nodes(m_model, m_path, m_animations, time, m_options.loop, m_warnings);
        apply_pointer_values(m_pose, m_model);
        SceneUpdate u;
        // The traversal and the material conversion write into a scratch scene.
        m_scene = Scene{};
        const bool materials = std::any_of(m_pose.values.begin(), m_pose.values.end(), [](const auto& v) {
            return v.collection == GltfPose::Collection::Materials;
        });
        if (materials) {
            convert_materials();  // the same textures: texture_index() finds each in m_texture_map
            std::copy(m_scene.materials.begin(), m_scene.materials.end(), scene.materials.begin());
            u.materials = true;
        }
        const size_t requests = m_requests.size();
        traverse_scene();
        if (m_requests.size() != requests || m_scene.instances.size() != scene.instances.size() ||
            m_scene.cameras.size() > scene.cameras.size() || m_scene.lights.size() > scene.lights.size())
            return std::nullopt;
        for (size_t i = 0; i < scene.instances.size(); ++i) {
            const Instance& now = m_scene.instances[i];
            Instance& was = scene.instances[i];
            if (now.mesh != was.mesh) return std::nullopt;
            if (now.world_from_object == was.world_from_object) continue;
            was.world_from_object = now.world_from_object;
            u.instances.push_back(uint32_t(i));
        }
        repose_meshes(scene, u);
        // The file's cameras and lights come first (the defaults and the environment's lights after).
        std::copy(m_scene.cameras.begin(), m_scene.cameras.end(), scene.cameras.begin());
        if (m_scene.cameras.empty() && !scene.cameras.empty() && scene.cameras[0].is_default)
            scene.cameras[0] = default_camera(scene.world_bounds());
        std::copy(m_scene.lights.begin(), m_scene.lights.end(), scene.lights.begin());
        u.cameras = true;
        u.lights = !m_scene.lights.empty();
        scene.time = time;
        m_scene = Scene{};
        std::swap(log, m_warnings);
        log.flush_to(scene);
        return u;
    }

private:
    /// KHR_materials_variants: the chosen variant's materials written into the primitives before
    /// anything reads them; the file's variants recorded for `whitted info`.
    void choose_variant() {
        if (!m_options.variant.empty()) apply_material_variant(m_model, m_path, m_options.variant);
        m_scene.variants = material_variants(m_model);
        m_scene.variant = m_options.variant;
    }

    /// repose(): each deforming mesh posed from its rest geometry, in parallel; the vertices are
    /// written into the Scene's arrays in place.
    void repose_meshes(Scene& scene, SceneUpdate& u) {
        for (size_t i = 0; i < m_rest.size(); ++i)
            if (!m_rest[i].positions.empty()) u.meshes.push_back(uint32_t(i));
        std::vector<WarningLog> logs(u.meshes.size());
        tbb::parallel_for(size_t(0), u.meshes.size(), [&](size_t d) {
            Mesh& rest = m_rest[u.meshes[d]];
            Mesh posed;
            posed.positions = rest.positions;
            posed.normals = rest.normals;
            posed.tangents = rest.tangents;
            posed.indices = std::move(rest.indices);  // borrowed (smooth normals, zero-area count)
            finish_geometry(m_requests[u.meshes[d]], posed, logs[d], false, &m_bindings[u.meshes[d]]);
            rest.indices = std::move(posed.indices);
            Mesh& out = scene.meshes[u.meshes[d]];
            std::copy(posed.positions.begin(), posed.positions.end(), out.positions.begin());
            out.normals = std::move(posed.normals);
            out.tangents = std::move(posed.tangents);
        });
        for (const WarningLog& l : logs) m_warnings.append(l);
    }

    template <typename... Args>
    [[noreturn]] void fail(const std::string& pointer, fmt::format_string<Args...> f, Args&&... args) const {
        throw Error(file_loc(m_path, pointer), fmt::format(f, std::forward<Args>(args)...));
    }

    // ---- parsing ------------------------------------------------------------------------------
    void load_model(std::span<const uint8_t> bytes) {
        if (bytes.empty()) fail("", "empty file (0 bytes)");
        if (bytes.size() > m_options.max_memory)
            fail("", "file of {} bytes exceeds the memory limit of {} bytes", bytes.size(), m_options.max_memory);
        std::string ext = std::filesystem::path(m_path).extension().string();
        std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
        bool binary = ext == ".glb";
        if (!binary && bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0) {
            m_scene.warn("the file is binary glTF (GLB) despite its .gltf extension: read as GLB");
            binary = true;
        }
        if (binary) {
            check_glb_container(m_path, bytes, m_scene);
        } else if (bytes.size() >= 3 && bytes[0] == 0xEF && bytes[1] == 0xBB && bytes[2] == 0xBF) {
            // glTF 2.0 spec 3.2: "JSON must use UTF-8 encoding without BOM" (validator: INVALID_JSON).
            fail("", "invalid JSON: the file starts with a UTF-8 byte order mark, which glTF forbids");
        }
        // JSON nesting: the whole file, or the GLB JSON chunk (its length was checked above).
        const size_t json_offset = binary ? 20 : 0;
        const size_t json_size = binary ? size_t(load_u32(bytes.data() + 12)) : bytes.size();
        const JsonOutline outline =
            json_outline(reinterpret_cast<const char*>(bytes.data()) + json_offset, json_size, kMaxJsonDepth);
        if (outline.depth > kMaxJsonDepth)
            fail("", "invalid JSON: arrays/objects nested deeper than {} levels", kMaxJsonDepth);

        // A required extension whitted cannot honour is reported as that, before tinygltf gets to
        // complain about its consequences (a primitive of an unknown codec has accessors without
        // bufferView).
        refuse_unsupported_required(reinterpret_cast<const char*>(bytes.data()) + json_offset, json_size);

        // Compressed geometry: EXT_meshopt_compression's fallback buffers carry no data (they get a
        // uri the file callbacks serve as zeros), a Draco primitive's indices accessor has no
        // bufferView (it moves out of tinygltf's sight); both are decoded after parsing.
        // KHR_animation_pointer targets get the node tinygltf insists on (-1).
        const std::optional<std::vector<uint8_t>> rewritten = prepare_for_tinygltf(bytes, binary, json_offset, json_size);
        const std::span<const uint8_t> file = rewritten ? std::span<const uint8_t>(*rewritten) : bytes;

        m_loader.keep_bytes = m_options.load_textures;
        m_loader.max_memory = m_options.max_memory;
        std::error_code ec;
        std::filesystem::path abs = std::filesystem::absolute(m_path, ec);
        m_base_dir = (ec ? std::filesystem::path(m_path) : abs).lexically_normal().parent_path().string();
        m_uri_policy.base = m_base_dir;
        m_uri_policy.allow_outside = m_options.allow_outside_uris;
        m_uri_policy.max_bytes = m_options.max_memory;
        // Reserved, the vectors are written once instead of moved through every doubling.
        reserve_for(m_model.accessors, outline.accessors, m_options.max_memory);
        reserve_for(m_model.bufferViews, outline.buffer_views, m_options.max_memory);
        reserve_for(m_model.meshes, outline.meshes, m_options.max_memory);
        reserve_for(m_model.nodes, outline.nodes, m_options.max_memory);
        reserve_for(m_model.materials, outline.materials, m_options.max_memory);
        tinygltf::TinyGLTF parser;
        parser.SetImageLoader(&capture_image, &m_loader);
        parser.SetFsCallbacks(
            {&policy_file_exists, &tinygltf::ExpandFilePath, &policy_read_file, &refuse_write, &m_uri_policy});

        std::string err, warn;
        bool ok = false;
        try {
            if (binary)
                ok = parser.LoadBinaryFromMemory(&m_model, &err, &warn, file.data(), unsigned(file.size()),
                                                 m_base_dir);
            else
                ok = parser.LoadASCIIFromString(&m_model, &err, &warn, reinterpret_cast<const char*>(file.data()),
                                                unsigned(file.size()), m_base_dir);
        } catch (const std::bad_alloc&) {
            fail("", "out of memory while parsing");
        } catch (const std::exception& e) {
            fail("", "glTF parse error: {}", one_line(e.what()));
        }
        // tinygltf 2.7 reports a skin without inverseBindMatrices as an error, though glTF 2.0
        // (3.7.3) makes them optional (identity matrices); it parses the skin all the same (-1).
        const std::string no_inverse_bind = "'inverseBindMatrices' property is missing in Skin.\n";
        for (size_t at; (at = err.find(no_inverse_bind)) != std::string::npos;) err.erase(at, no_inverse_bind.size());
        // Refusals by the URI policy or the image header check explain a failure better than tinygltf.
        if (!m_uri_policy.refused.empty()) fail("", "{}", m_uri_policy.refused);
        if (!m_loader.refused.empty()) {
            const size_t colon = m_loader.refused.find(':');
            fail(m_loader.refused.substr(0, colon), "image refused: {}", m_loader.refused.substr(colon + 2));
        }
        if (!ok || !err.empty()) {
            const std::string msg = one_line(err.empty() ? "tinygltf failed without a message" : err);
            if (msg.find("'uri' is missing from non binary glTF file buffer") != std::string::npos)
                fail("", "a buffer has no uri: only a GLB file's first buffer may omit it (it is the BIN chunk)");
            // Name the resource when tinygltf could not find one (external .bin or image).
            const std::string not_found = "File not found : ";
            if (const size_t at = err.find(not_found); at != std::string::npos) {
                std::string name = err.substr(at + not_found.size());
                name = name.substr(0, name.find('\n'));
                if (name.rfind("data:", 0) == 0)
                    fail("", "invalid data URI '{}' (expected data:<mime type>;base64,<data>)",
                         shorten_data_uris(name));
                fail("", "missing resource '{}' (looked in '{}')", name, m_base_dir);
            }
            if (msg.find("Failed to decode 'uri'") != std::string::npos)
                fail("", "{} (malformed base64, or the decoded size differs from the buffer's byteLength)", msg);
            if (msg.find("Invalid `byteStride' value") != std::string::npos)
                fail("", "a bufferView byteStride is not a multiple of 4 in [4, 252] ({})", msg);
            if (msg.find("json.exception") != std::string::npos || msg.find("JSON") != std::string::npos)
                fail("", "invalid JSON: {}", msg);
            fail("", "glTF parse error: {}", msg);
        }
        decode_meshopt_views(m_model, m_path);
        m_scene.compressed = meshopt_primitives(m_model);
        for (CompressedPrimitive& r : decode_draco_primitives(m_model, m_path, m_options.max_memory))
            m_scene.compressed.push_back(std::move(r));
        // tinygltf reports an image it could not find as a warning; whitted treats it as an error
        // (check_images_present), so only keep the other warnings.
        size_t start = 0;
        while (start < warn.size()) {
            size_t end = warn.find('\n', start);
            if (end == std::string::npos) end = warn.size();
            const std::string line = warn.substr(start, end - start);
            if (!line.empty() && line.find("File not found") == std::string::npos &&
                line.find("Failed to load external 'uri' for image") == std::string::npos)
                m_warnings.add("tinygltf:" + line, "tinygltf: " + line);
            start = end + 1;
        }
        m_loader.images.resize(m_model.images.size());
    }

    void check_images_present() const {
        for (size_t i = 0; i < m_model.images.size(); ++i) {
            if (m_loader.images[i].seen) continue;
            const tinygltf::Image& img = m_model.images[i];
            if (!img.uri.empty())
                fail(fmt::format("/images/{}/uri", i), "image file '{}' not found (looked in '{}')", img.uri,
                     m_base_dir);
            fail(fmt::format("/images/{}", i), "image data missing");
        }
    }

    // ---- extensions ---------------------------------------------------------------------------
    /// The JSON's top-level extensionsRequired, read on its own (the rest is skipped, not stored):
    /// any that whitted refuses is the error. JSON that does not parse is left to tinygltf.
    void refuse_unsupported_required(const char* json, size_t size) const {
        if (std::string_view(json, size).find("extensionsRequired") == std::string_view::npos) return;
        const nlohmann::json::parser_callback_t keep_required = [](int depth, nlohmann::json::parse_event_t event,
                                                                  nlohmann::json& parsed) {
            return !(depth == 1 && event == nlohmann::json::parse_event_t::key && parsed != "extensionsRequired");
        };
        const nlohmann::json doc = nlohmann::json::parse(json, json + size, keep_required, false);
        if (!doc.is_object() || !doc.contains("extensionsRequired") || !doc["extensionsRequired"].is_array()) return;
        const nlohmann::json& required = doc["extensionsRequired"];
        for (size_t i = 0; i < required.size(); ++i) {
            if (!required[i].is_string()) continue;
            const std::string name = required[i].get<std::string>();
            const ExtensionPolicy policy = extension_policy(name);
            if (policy.support != ExtensionSupport::Supported && policy.refuse_if_required)
                fail(fmt::format("/extensionsRequired/{}", i), "required extension {} is not supported by whitted ({})",
                     name, policy.note);
        }
    }

    void classify_extensions() {
        std::vector<std::string> names = m_model.extensionsUsed;
        for (const std::string& r : m_model.extensionsRequired)
            if (std::find(names.begin(), names.end(), r) == names.end()) names.push_back(r);
        for (size_t i = 0; i < names.size(); ++i) {
            const std::string& name = names[i];
            // A required one whitted refuses was reported before parsing (refuse_unsupported_required).
            const bool required = std::find(m_model.extensionsRequired.begin(), m_model.extensionsRequired.end(),
                                            name) != m_model.extensionsRequired.end();
            const ExtensionPolicy policy = extension_policy(name);
            m_scene.extensions.push_back({name, policy.support, required, policy.note});
            if (policy.support == ExtensionSupport::Ignored)
                m_warnings.add("ext:" + name, fmt::format("extension {} ignored: {}", name, policy.note));
        }
    }

    // ---- the pose ------------------------------------------------------------------------------
    /// Every node's transform and morph weights at the chosen time (gltf_animation.h).
    void pose() {
        m_animations = choose_animations(m_model, m_path, m_options.animation);
        m_pose = pose_nodes(m_model, m_path, m_animations, m_options.time, m_options.loop, m_warnings);
        apply_pointer_values(m_pose, m_model);
        m_scene.time = m_options.time;
    }

    // ---- materials and texture references -----------------------------------------------------
    double number(const tinygltf::Value* object, const char* key, double fallback, const std::string& ptr) const {
        const tinygltf::Value* v = find_member(object, key);
        if (v == nullptr) return fallback;
        if (!v->IsNumber()) fail(ptr + "/" + key, "{} is not a number", key);
        return v->GetNumberAsDouble();
    }

    Color color3(const tinygltf::Value* object, const char* key, Color fallback, const std::string& ptr) const {
        const tinygltf::Value* v = find_member(object, key);
        if (v == nullptr) return fallback;
        if (!v->IsArray() || v->ArrayLen() != 3) fail(ptr + "/" + key, "{} must be an array of 3 numbers", key);
        Color c;
        for (int k = 0; k < 3; ++k) {
            const tinygltf::Value* e = find_element(v, size_t(k));
            if (!e->IsNumber()) fail(fmt::format("{}/{}/{}", ptr, key, k), "not a number");
            c[k] = float(e->GetNumberAsDouble());
        }
        return c;
    }

    /// Scene texture for (glTF texture, sRGB-ness), created on first use; -1 when the texture has
    /// no image whitted can decode.
    int32_t texture_index(int gltf_texture, bool srgb) {
        const auto key = std::make_pair(gltf_texture, srgb);
        if (auto it = m_texture_map.find(key); it != m_texture_map.end()) return it->second;
        const tinygltf::Texture& t = m_model.textures[size_t(gltf_texture)];
        int32_t result = -1;
        // EXT_texture_webp's image is the preferred one; the core source is its fallback.
        int source = t.source;
        if (const auto webp = t.extensions.find("EXT_texture_webp"); webp != t.extensions.end())
            if (const tinygltf::Value* v = find_member(&webp->second, "source"); v != nullptr) as_int(v, source);
        if (source < 0) {
            std::string exts;
            for (const auto& [name, v] : t.extensions) exts += (exts.empty() ? "" : ", ") + name;
            m_warnings.add("texture-no-source",
                           fmt::format("/textures/{}: no image whitted decodes (PNG, JPEG, WebP){}: texture not used",
                                       gltf_texture, exts.empty() ? "" : " - only " + exts));
        } else {
            Texture tex;
            const tinygltf::Image& img = m_model.images[size_t(source)];
            tex.name = !t.name.empty()     ? t.name
                       : !img.name.empty() ? img.name
                       : !img.uri.empty()  ? img.uri
                                           : fmt::format("image {}", source);
            tex.srgb = srgb;
            tex.image = source;
            if (t.sampler >= 0) {
                const tinygltf::Sampler& s = m_model.samplers[size_t(t.sampler)];
                auto wrap = [](int w) {
                    return w == 33071   ? WrapMode::ClampToEdge
                           : w == 33648 ? WrapMode::MirroredRepeat
                                        : WrapMode::Repeat;
                };
                tex.wrap_s = wrap(s.wrapS);
                tex.wrap_t = wrap(s.wrapT);
                tex.mag_filter = s.magFilter == 9728 ? FilterMode::Nearest : FilterMode::Linear;
                // 9728 NEAREST, 9729 LINEAR (no mips); 9984 NEAREST_MIPMAP_NEAREST, 9986 NEAREST_MIPMAP_LINEAR.
                tex.min_filter = (s.minFilter == 9728 || s.minFilter == 9984 || s.minFilter == 9986)
                                     ? FilterMode::Nearest
                                     : FilterMode::Linear;
                tex.use_mips = !(s.minFilter == 9728 || s.minFilter == 9729);
            }
            result = int32_t(m_scene.textures.size());
            m_scene.textures.push_back(std::move(tex));
        }
        m_texture_map.emplace(key, result);
        return result;
    }

    /// A material's texture slot: core fields plus KHR_texture_transform.
    TextureRef texture_ref(int index, int tex_coord, double scale, const tinygltf::ExtensionMap& extensions, bool srgb,
                           const std::string& ptr) {
        TextureRef ref;
        if (index < 0) return ref;
        // validate_gltf() resolved every slot; this keeps texture_index() in bounds on its own.
        if (size_t(index) >= m_model.textures.size())
            fail(ptr + "/index", "unresolved reference: texture {} does not exist (the file has {})", index,
                 m_model.textures.size());
        ref.scale = float(scale);
        int uv = tex_coord;
        if (const tinygltf::Value* xf = find_extension(extensions, "KHR_texture_transform")) {
            const std::string xptr = ptr + "/extensions/KHR_texture_transform";
            if (const tinygltf::Value* o = find_member(xf, "offset"))
                ref.transform.offset = {float(find_element(o, 0)->GetNumberAsDouble()),
                                        float(find_element(o, 1)->GetNumberAsDouble())};
            if (const tinygltf::Value* s = find_member(xf, "scale"))
                ref.transform.scale = {float(find_element(s, 0)->GetNumberAsDouble()),
                                       float(find_element(s, 1)->GetNumberAsDouble())};
            ref.transform.rotation = float(number(xf, "rotation", 0.0, xptr));
            int override_uv = -1;
            if (as_int(find_member(xf, "texCoord"), override_uv)) uv = override_uv;
        }
        if (uv > 1) {
            m_warnings.add("texcoord", fmt::format("{}: TEXCOORD_{} is not supported (TEXCOORD_0 and _1 only): "
                                                   "TEXCOORD_0 used",
                                                   ptr, uv));
            uv = 0;
        }
        ref.uv_set = uint32_t(uv);
        ref.texture = texture_index(index, srgb);
        return ref;
    }

    /// A textureInfo kept as raw JSON by tinygltf (inside material extensions); `with_scale` reads
    /// a normalTextureInfo's "scale" into TextureRef::scale.
    TextureRef texture_ref_value(const tinygltf::Value* info, bool srgb, const std::string& ptr,
                                 bool with_scale = false) {
        if (info == nullptr) return {};
        int index = -1, tex_coord = 0;
        if (!as_int(find_member(info, "index"), index) || index < 0)
            fail(ptr + "/index", "textureInfo index must be a non-negative integer");
        as_int(find_member(info, "texCoord"), tex_coord);
        tinygltf::ExtensionMap exts;
        if (const tinygltf::Value* xf = find_member(find_member(info, "extensions"), "KHR_texture_transform"))
            exts["KHR_texture_transform"] = *xf;
        const double scale = with_scale ? factor(info, "scale", 1.f, ptr) : 1.0;
        return texture_ref(index, tex_coord, scale, exts, srgb, ptr);
    }

    /// Reads the number (out.size() == 1) or array of out.size() numbers `key` of a material
    /// extension into `out`, which holds the defaults and is left alone when `key` is absent. Not a
    /// finite number is an error; a component outside [lo, hi] is clamped, with one warning for the
    /// (material, field).
    void read_factors(const tinygltf::Value* ext, const char* key, std::span<float> out, const std::string& ptr,
                      double lo, double hi) {
        const tinygltf::Value* v = find_member(ext, key);
        if (v == nullptr) return;
        const std::string at = ptr + "/" + key;
        if (out.size() == 1 && !v->IsNumber()) fail(at, "{} is not a number", key);
        if (out.size() > 1 && (!v->IsArray() || v->ArrayLen() != out.size()))
            fail(at, "{} must be an array of {} numbers", key, out.size());
        std::string given, clamped;
        bool clamps = false;
        for (size_t k = 0; k < out.size(); ++k) {
            const tinygltf::Value* e = out.size() == 1 ? v : find_element(v, k);
            const std::string elem_at = out.size() == 1 ? at : fmt::format("{}/{}", at, k);
            if (!e->IsNumber()) fail(elem_at, "not a number");
            const double d = e->GetNumberAsDouble();
            const double c = std::clamp(d, lo, hi);
            if (!std::isfinite(d) || !std::isfinite(float(c))) fail(elem_at, "{} {} is not a finite number", key, d);
            clamps |= c != d;
            given += fmt::format("{}{}", k ? ", " : "", d);
            clamped += fmt::format("{}{}", k ? ", " : "", c);
            out[k] = float(c);
        }
        if (!clamps) return;
        if (out.size() > 1) given = "(" + given + ")", clamped = "(" + clamped + ")";
        m_warnings.add("factor-clamped:" + at,
                       fmt::format("{}: {} outside [{}, {}], clamped to {}", at, given, lo, hi, clamped));
    }

    /// A scalar factor of a material extension (read_factors), `fallback` when absent.
    float factor(const tinygltf::Value* ext, const char* key, float fallback, const std::string& ptr,
                 double lo = -kNoLimit, double hi = kNoLimit) {
        float v = fallback;
        read_factors(ext, key, std::span<float>(&v, 1), ptr, lo, hi);
        return v;
    }

    /// An RGB factor of a material extension with components in [0, 1] (read_factors).
    Color color_factor(const tinygltf::Value* ext, const char* key, Color fallback, const std::string& ptr) {
        float c[3] = {fallback.x, fallback.y, fallback.z};
        read_factors(ext, key, c, ptr, 0.0, 1.0);
        return {c[0], c[1], c[2]};
    }

    void convert_materials() {
        // Scene materials are index-aligned with the file's /materials; the default material
        // (when needed) comes last.
        for (size_t i = 0; i < m_model.materials.size(); ++i) {
            const tinygltf::Material& g = m_model.materials[i];
            const std::string ptr = fmt::format("/materials/{}", i);
            const auto& pbr = g.pbrMetallicRoughness;
            Material m;
            m.name = g.name.empty() ? fmt::format("material {}", i) : g.name;
            const std::string eptr = ptr + "/extensions/";
            // A file giving specular-glossiness asks for it; its pbrMetallicRoughness is the
            // fallback for viewers without the extension (the extension's "Best practices").
            if (const tinygltf::Value* e = find_extension(g.extensions, "KHR_materials_pbrSpecularGlossiness")) {
                convert_specular_glossiness(e, eptr + "KHR_materials_pbrSpecularGlossiness", m);
            } else {
                m.base_color = {float(pbr.baseColorFactor[0]), float(pbr.baseColorFactor[1]),
                                float(pbr.baseColorFactor[2]), float(pbr.baseColorFactor[3])};
                m.metallic = float(pbr.metallicFactor);
                m.roughness = float(pbr.roughnessFactor);
                m.base_color_texture =
                    texture_ref(pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord, 1.0,
                                pbr.baseColorTexture.extensions, true, ptr + "/pbrMetallicRoughness/baseColorTexture");
                m.metallic_roughness_texture =
                    texture_ref(pbr.metallicRoughnessTexture.index, pbr.metallicRoughnessTexture.texCoord, 1.0,
                                pbr.metallicRoughnessTexture.extensions, false,
                                ptr + "/pbrMetallicRoughness/metallicRoughnessTexture");
            }
            m.normal_texture = texture_ref(g.normalTexture.index, g.normalTexture.texCoord, g.normalTexture.scale,
                                           g.normalTexture.extensions, false, ptr + "/normalTexture");
            m.occlusion_texture =
                texture_ref(g.occlusionTexture.index, g.occlusionTexture.texCoord, g.occlusionTexture.strength,
                            g.occlusionTexture.extensions, false, ptr + "/occlusionTexture");
            m.emissive = {float(g.emissiveFactor[0]), float(g.emissiveFactor[1]), float(g.emissiveFactor[2])};
            m.emissive_texture = texture_ref(g.emissiveTexture.index, g.emissiveTexture.texCoord, 1.0,
                                             g.emissiveTexture.extensions, true, ptr + "/emissiveTexture");
            m.alpha_mode = g.alphaMode == "MASK"    ? AlphaMode::Mask
                           : g.alphaMode == "BLEND" ? AlphaMode::Blend
                                                    : AlphaMode::Opaque;
            m.alpha_cutoff = float(g.alphaCutoff);
            m.double_sided = g.doubleSided;

            if (const tinygltf::Value* e = find_extension(g.extensions, "KHR_materials_emissive_strength"))
                m.emissive_strength =
                    float(number(e, "emissiveStrength", 1.0, eptr + "KHR_materials_emissive_strength"));
            if (find_extension(g.extensions, "KHR_materials_unlit") != nullptr) m.unlit = true;
            if (const tinygltf::Value* e = find_extension(g.extensions, "KHR_materials_transmission")) {
                const std::string p = eptr + "KHR_materials_transmission";
                m.transmission = float(number(e, "transmissionFactor", 0.0, p));
                m.transmission_texture =
                    texture_ref_value(find_member(e, "transmissionTexture"), false, p + "/transmissionTexture");
            }
            if (const tinygltf::Value* e = find_extension(g.extensions, "KHR_materials_ior"))
                m.ior = float(number(e, "ior", 1.5, eptr + "KHR_materials_ior"));
            if (const tinygltf::Value* e = find_extension(g.extensions, "KHR_materials_volume")) {
                const std::string p = eptr + "KHR_materials_volume";
                m.thickness = float(number(e, "thicknessFactor", 0.0, p));
                m.has_volume = m.thickness > 0.f;
                m.attenuation_color = color3(e, "attenuationColor", Color(1.f), p);
                const double d = number(e, "attenuationDistance", double(kInfinity), p);
                if (!(d > 0)) fail(p + "/attenuationDistance", "attenuationDistance {} must be positive", d);
                m.attenuation_distance = float(d);
                if (find_member(e, "thicknessTexture") != nullptr)
                    m_warnings.add("thickness-texture", fmt::format("{}: KHR_materials_volume thicknessTexture not "
                                                                    "used (thicknessFactor only)",
                                                                    ptr));
            }
            if (const tinygltf::Value* e = find_extension(g.extensions, "KHR_materials_specular")) {
                const std::string p = eptr + "KHR_materials_specular";
                m.specular = float(number(e, "specularFactor", 1.0, p));
                m.specular_color = color3(e, "specularColorFactor", Color(1.f), p);
                m.specular_texture =
                    texture_ref_value(find_member(e, "specularTexture"), false, p + "/specularTexture");
                m.specular_color_texture =
                    texture_ref_value(find_member(e, "specularColorTexture"), true, p + "/specularColorTexture");
            }
            convert_layers(g.extensions, eptr, m);
            m_scene.materials.push_back(std::move(m));
        }
    }

    /// The layered extensions (clearcoat, sheen, iridescence, anisotropy, dispersion, diffuse
    /// transmission) into `m`; absent ones keep scene.h's defaults, which switch the layer off.
    /// Channels and transfer functions are the extensions' own (their READMEs' property tables).
    void convert_layers(const tinygltf::ExtensionMap& extensions, const std::string& eptr, Material& m) {
        if (const tinygltf::Value* e = find_extension(extensions, "KHR_materials_clearcoat")) {
            const std::string p = eptr + "KHR_materials_clearcoat";
            m.clearcoat = factor(e, "clearcoatFactor", 0.f, p, 0.0, 1.0);
            m.clearcoat_texture = texture_ref_value(find_member(e, "clearcoatTexture"), false, p + "/clearcoatTexture");
            m.clearcoat_roughness = factor(e, "clearcoatRoughnessFactor", 0.f, p, 0.0, 1.0);
            m.clearcoat_roughness_texture =
                texture_ref_value(find_member(e, "clearcoatRoughnessTexture"), false, p + "/clearcoatRoughnessTexture");
            m.clearcoat_normal_texture = texture_ref_value(find_member(e, "clearcoatNormalTexture"), false,
                                                           p + "/clearcoatNormalTexture", true);
        }
        if (const tinygltf::Value* e = find_extension(extensions, "KHR_materials_sheen")) {
            const std::string p = eptr + "KHR_materials_sheen";
            m.sheen_color = color_factor(e, "sheenColorFactor", Color(0.f), p);
            m.sheen_color_texture =
                texture_ref_value(find_member(e, "sheenColorTexture"), true, p + "/sheenColorTexture");
            m.sheen_roughness = factor(e, "sheenRoughnessFactor", 0.f, p, 0.0, 1.0);
            m.sheen_roughness_texture =
                texture_ref_value(find_member(e, "sheenRoughnessTexture"), false, p + "/sheenRoughnessTexture");
        }
        if (const tinygltf::Value* e = find_extension(extensions, "KHR_materials_iridescence")) {
            const std::string p = eptr + "KHR_materials_iridescence";
            m.iridescence = factor(e, "iridescenceFactor", 0.f, p, 0.0, 1.0);
            m.iridescence_texture =
                texture_ref_value(find_member(e, "iridescenceTexture"), false, p + "/iridescenceTexture");
            m.iridescence_ior = factor(e, "iridescenceIor", 1.3f, p);
            if (!(m.iridescence_ior > 0.f))
                fail(p + "/iridescenceIor", "iridescenceIor {} must be positive", m.iridescence_ior);
            m.iridescence_thickness_min = factor(e, "iridescenceThicknessMinimum", 100.f, p);
            m.iridescence_thickness_max = factor(e, "iridescenceThicknessMaximum", 400.f, p);
            // The minimum may exceed the maximum (the extension allows it): mix(min, max, g) then
            // runs from thick to thin, so both are kept as given.
            if (m.iridescence_thickness_min < 0.f)
                fail(p + "/iridescenceThicknessMinimum", "iridescenceThicknessMinimum {} nm is negative",
                     m.iridescence_thickness_min);
            if (m.iridescence_thickness_max < 0.f)
                fail(p + "/iridescenceThicknessMaximum", "iridescenceThicknessMaximum {} nm is negative",
                     m.iridescence_thickness_max);
            m.iridescence_thickness_texture = texture_ref_value(find_member(e, "iridescenceThicknessTexture"), false,
                                                                p + "/iridescenceThicknessTexture");
            // Valid glTF, and rendered as the extension's mix says, but most likely a slip: said once.
            if (m.iridescence_thickness_min > m.iridescence_thickness_max)
                m_warnings.add("iridescence-range:" + p,
                               fmt::format("{}/iridescenceThicknessMinimum: {} nm above iridescenceThicknessMaximum {} "
                                           "nm, kept as given ({})",
                                           p, m.iridescence_thickness_min, m.iridescence_thickness_max,
                                           m.iridescence_thickness_texture.valid()
                                               ? "the film thins where the thickness texture's green rises"
                                               : "unused: without iridescenceThicknessTexture the thickness is the maximum"));
        }
        if (const tinygltf::Value* e = find_extension(extensions, "KHR_materials_anisotropy")) {
            const std::string p = eptr + "KHR_materials_anisotropy";
            m.anisotropy_strength = factor(e, "anisotropyStrength", 0.f, p, 0.0, 1.0);
            m.anisotropy_rotation = factor(e, "anisotropyRotation", 0.f, p);
            m.anisotropy_texture =
                texture_ref_value(find_member(e, "anisotropyTexture"), false, p + "/anisotropyTexture");
        }
        if (const tinygltf::Value* e = find_extension(extensions, "KHR_materials_dispersion")) {
            const std::string p = eptr + "KHR_materials_dispersion";
            m.dispersion = factor(e, "dispersion", 0.f, p);
            if (m.dispersion < 0.f)
                fail(p + "/dispersion", "dispersion {} is negative (it is 20 / Abbe number, 0 = none)", m.dispersion);
        }
        if (const tinygltf::Value* e = find_extension(extensions, "KHR_materials_diffuse_transmission")) {
            const std::string p = eptr + "KHR_materials_diffuse_transmission";
            m.diffuse_transmission = factor(e, "diffuseTransmissionFactor", 0.f, p, 0.0, 1.0);
            m.diffuse_transmission_texture = texture_ref_value(find_member(e, "diffuseTransmissionTexture"), false,
                                                               p + "/diffuseTransmissionTexture");
            m.diffuse_transmission_color = color_factor(e, "diffuseTransmissionColorFactor", Color(1.f), p);
            m.diffuse_transmission_color_texture = texture_ref_value(find_member(e, "diffuseTransmissionColorTexture"),
                                                                     true, p + "/diffuseTransmissionColorTexture");
        }
    }

    /// KHR_materials_pbrSpecularGlossiness into `m`, with the core fields set to their nearest
    /// metallic-roughness reading (metallic 0, roughness 1 - glossiness) for code that reads only those.
    void convert_specular_glossiness(const tinygltf::Value* e, const std::string& p, Material& m) {
        m.specular_glossiness = true;
        float diffuse[4] = {1.f, 1.f, 1.f, 1.f};
        read_factors(e, "diffuseFactor", diffuse, p, 0.0, 1.0);
        m.base_color = {diffuse[0], diffuse[1], diffuse[2], diffuse[3]};
        // Both textures are sRGB-encoded in RGB; Texture::srgb leaves alpha (coverage, glossiness) linear.
        m.base_color_texture = texture_ref_value(find_member(e, "diffuseTexture"), true, p + "/diffuseTexture");
        m.sg_specular = color_factor(e, "specularFactor", Color(1.f), p);
        m.glossiness = factor(e, "glossinessFactor", 1.f, p, 0.0, 1.0);
        m.specular_glossiness_texture =
            texture_ref_value(find_member(e, "specularGlossinessTexture"), true, p + "/specularGlossinessTexture");
        m.metallic = 0.f;
        m.roughness = 1.f - m.glossiness;
    }

    uint32_t default_material() {
        if (m_default_material < 0) {
            Material m;  // glTF default: white, metallic 1, roughness 1 (scene.h defaults)
            m.name = "default";
            m_default_material = int(m_scene.materials.size());
            m_scene.materials.push_back(std::move(m));
        }
        return uint32_t(m_default_material);
    }

    // ---- scene traversal ----------------------------------------------------------------------
    int chosen_scene() {
        const int n = int(m_model.scenes.size());
        if (m_options.scene_index >= 0) {
            if (m_options.scene_index >= n)
                fail("/scenes", "scene {} requested but the file has {} scene(s)", m_options.scene_index, n);
            return m_options.scene_index;
        }
        if (m_model.defaultScene >= 0) return m_model.defaultScene;
        return n > 0 ? 0 : -1;
    }

    /// True when the primitive yields triangles (mode, POSITION and count all allow it).
    bool renderable(const tinygltf::Primitive& p) const {
        if (p.mode != TINYGLTF_MODE_TRIANGLES && p.mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
            p.mode != TINYGLTF_MODE_TRIANGLE_FAN)
            return false;
        auto pos = p.attributes.find("POSITION");
        if (pos == p.attributes.end()) return false;
        const size_t n =
            p.indices >= 0 ? m_model.accessors[size_t(p.indices)].count : m_model.accessors[size_t(pos->second)].count;
        return triangle_count_for_mode(p.mode, n) > 0;
    }

    uint32_t mesh_for(int mesh, int primitive, bool mirrored, int node = -1) {
        const MeshKey key{mesh, primitive, mirrored, node};
        auto [it, inserted] = m_mesh_map.emplace(key, uint32_t(m_requests.size()));
        if (inserted) m_requests.push_back(key);
        return it->second;
    }

    /// Instances multiply (nodes x primitives x EXT_mesh_gpu_instancing counts): a tiny file could
    /// ask for billions, so their memory is checked as they are placed, before allocating.
    void check_instance_budget(int node, size_t more) const {
        const size_t per_instance = sizeof(Instance) + 32;  // as check_memory() counts them
        const size_t have = m_scene.instances.size();
        const size_t allowed = m_options.max_memory / per_instance;
        if (more > allowed || have + more > allowed)
            fail(fmt::format("/nodes/{}", node),
                 "the node graph places more than {} instances, more than the memory limit of {} MiB allows", allowed,
                 m_options.max_memory >> 20);
    }

    /// One Instance per renderable primitive of `mesh`, using the mirrored mesh copy when the
    /// transform has a negative determinant.
    void place_mesh(int node, const std::string& label, int mesh, const Mat4d& world) {
        const auto& prims = m_model.meshes[size_t(mesh)].primitives;
        // A skinned mesh is posed in world space by its joints: its node's transform does not apply.
        const bool skinned = m_model.nodes[size_t(node)].skin >= 0;
        const Mat4d& placed = skinned ? Mat4d::identity() : world;
        const bool mirrored = placed.det3() < 0;
        for (size_t p = 0; p < prims.size(); ++p) {
            if (!renderable(prims[p])) continue;
            check_instance_budget(node, 1);
            Instance inst;
            inst.mesh = mesh_for(mesh, int(p), mirrored, deformed(m_model, node, int(p)) ? node : -1);
            inst.world_from_object = placed;
            inst.node_name = label;
            inst.node = node;
            inst.moving = !skinned && m_pose.moving[size_t(node)];
            m_scene.instances.push_back(std::move(inst));
        }
    }

    /// EXT_mesh_gpu_instancing: one placement per instance, world * T * R * S.
    void place_gpu_instances(int node, int mesh, const Mat4d& world, const tinygltf::Value* ext) {
        const tinygltf::Value* attrs = find_member(ext, "attributes");
        int acc[3] = {-1, -1, -1};  // TRANSLATION, ROTATION, SCALE
        as_int(find_member(attrs, "TRANSLATION"), acc[0]);
        as_int(find_member(attrs, "ROTATION"), acc[1]);
        as_int(find_member(attrs, "SCALE"), acc[2]);
        size_t count = 0;
        for (int a : acc)
            if (a >= 0) count = m_model.accessors[size_t(a)].count;
        const std::string label = node_label(m_model, node);
        if (count == 0) {
            place_mesh(node, label, mesh, world);
            return;
        }
        std::vector<Vec3d> t(count, Vec3d(0.0)), s(count, Vec3d(1.0));
        std::vector<std::array<double, 4>> r(count, {0, 0, 0, 1});
        if (acc[0] >= 0)
            for_each_element(accessor_data(m_model, acc[0]), [&](size_t i, const float* v) {
                t[i] = {v[0], v[1], v[2]};
            });
        if (acc[1] >= 0)
            for_each_element(accessor_data(m_model, acc[1]), [&](size_t i, const float* v) {
                r[i] = {v[0], v[1], v[2], v[3]};
            });
        if (acc[2] >= 0)
            for_each_element(accessor_data(m_model, acc[2]), [&](size_t i, const float* v) {
                s[i] = {v[0], v[1], v[2]};
            });
        const size_t prims = m_model.meshes[size_t(mesh)].primitives.size();
        check_instance_budget(node, prims > 0 && count > SIZE_MAX / prims ? SIZE_MAX : count * prims);
        m_scene.instances.reserve(m_scene.instances.size() + count * prims);
        for (size_t i = 0; i < count; ++i) {
            const auto& q = r[i];
            const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
            Mat4d rot;
            if (n > 1e-12)
                rot = Mat4d::rotate(q[0] / n, q[1] / n, q[2] / n, q[3] / n);
            else
                m_warnings.add("instancing-rotation",
                               fmt::format("/nodes/{}: EXT_mesh_gpu_instancing instance {} has a "
                                           "zero rotation quaternion: identity used",
                                           node, i));
            place_mesh(node, label, mesh, world * Mat4d::translate(t[i]) * rot * Mat4d::scale(s[i]));
        }
    }

    void place_camera(int node, const Mat4d& world) {
        const tinygltf::Camera& g = m_model.cameras[size_t(m_model.nodes[size_t(node)].camera)];
        Camera c;
        c.name = !g.name.empty() ? g.name : node_label(m_model, node);
        if (g.type == "perspective") {
            c.type = CameraType::Perspective;
            c.yfov = g.perspective.yfov;
            c.aspect = g.perspective.aspectRatio;
            c.znear = g.perspective.znear;
            c.zfar = g.perspective.zfar;
        } else {
            c.type = CameraType::Orthographic;
            c.xmag = std::fabs(g.orthographic.xmag);
            c.ymag = std::fabs(g.orthographic.ymag);
            c.aspect = c.xmag / c.ymag;
            c.znear = g.orthographic.znear;
            c.zfar = g.orthographic.zfar;
        }
        c.world_from_camera = world;
        m_scene.cameras.push_back(std::move(c));
    }

    void place_light(int node, int light, const Mat4d& world) {
        const tinygltf::Light& g = m_model.lights[size_t(light)];
        Light l;
        l.name = !g.name.empty() ? g.name : node_label(m_model, node);
        l.type = g.type == "directional" ? LightType::Directional
                 : g.type == "spot"      ? LightType::Spot
                                         : LightType::Point;
        if (g.color.size() == 3) l.color = {float(g.color[0]), float(g.color[1]), float(g.color[2])};
        // Renderer units are candela (point, spot) and lux (directional): see docs/lights.md.
        l.intensity = float(g.intensity);
        l.range = float(g.range);
        if (l.type == LightType::Spot) {
            l.inner_cone = float(g.spot.innerConeAngle);
            l.outer_cone = float(g.spot.outerConeAngle);
        }
        l.position = world.apply_point(Vec3d(0.0));
        l.direction = normalize(world.apply_vector({0, 0, -1}));
        if (l.direction == Vec3d(0.0)) {
            m_warnings.add("light-direction", fmt::format("/nodes/{}: light node transform collapses -Z: direction "
                                                          "(0, 0, -1) used",
                                                          node));
            l.direction = {0, 0, -1};
        }
        l.attenuation = l.type == LightType::Directional ? Attenuation::None : Attenuation::InverseSquare;
        m_scene.lights.push_back(std::move(l));
    }

    void traverse_scene() {
        const int s = chosen_scene();
        std::vector<int> roots;
        if (s >= 0) {
            roots = m_model.scenes[size_t(s)].nodes;
        } else if (!m_model.nodes.empty()) {
            // No scene at all: show every root node (the file gives no other hint).
            std::vector<char> is_child(m_model.nodes.size(), 0);
            for (const tinygltf::Node& n : m_model.nodes)
                for (int c : n.children) is_child[size_t(c)] = 1;
            for (size_t i = 0; i < m_model.nodes.size(); ++i)
                if (!is_child[i]) roots.push_back(int(i));
            m_warnings.add("no-scene", "the file defines no scene: every root node is shown");
        }
        // Depth-first, pre-order, children in file order (this is the camera and light order); the
        // world transforms are the pose's (scene roots are roots of the node forest).
        std::vector<int> stack(roots.rbegin(), roots.rend());
        while (!stack.empty()) {
            const int n = stack.back();
            stack.pop_back();
            const tinygltf::Node& node = m_model.nodes[size_t(n)];
            const Mat4d& world = m_pose.world[size_t(n)];
            if (node.mesh >= 0) {
                if (const tinygltf::Value* gi = find_extension(node.extensions, "EXT_mesh_gpu_instancing"))
                    place_gpu_instances(n, node.mesh, world, gi);
                else
                    place_mesh(n, node_label(m_model, n), node.mesh, world);
            }
            if (node.camera >= 0) place_camera(n, world);
            if (const tinygltf::Value* lp = find_extension(node.extensions, "KHR_lights_punctual")) {
                int light = -1;
                as_int(find_member(lp, "light"), light);
                place_light(n, light, world);
            }
            for (auto c = node.children.rbegin(); c != node.children.rend(); ++c) stack.push_back(*c);
        }
    }

    // ---- memory budget ------------------------------------------------------------------------
    /// Why a primitive needs a tangent frame, and the UV set tangents are generated from when the
    /// file gives none (uv -1: no need).
    struct TangentNeed {
        int uv = -1;
        const char* reason = "";  ///< for the warning when the primitive lacks that UV set
        const char* effect = "";
    };

    /// A normal texture, anisotropy (strength > 0) and an active clearcoat's normal texture each
    /// need the tangent frame; the normal texture's UV set wins (the extensions ask theirs to be
    /// the same), then the anisotropy texture's, then the clearcoat normal texture's, else 0.
    TangentNeed tangent_need(const tinygltf::Primitive& p) const {
        if (p.material < 0) return {};
        const Material& m = m_scene.materials[size_t(p.material)];
        if (m.normal_texture.valid())
            return {int(m.normal_texture.uv_set), "the normal texture uses", "normal map has no effect"};
        const bool anisotropic = m.anisotropy_strength > 0.f;
        const bool coat_normal = m.clearcoat > 0.f && m.clearcoat_normal_texture.valid();
        if (anisotropic && m.anisotropy_texture.valid())
            return {int(m.anisotropy_texture.uv_set), "the anisotropy texture uses", "anisotropy has no direction"};
        if (coat_normal)
            return {int(m.clearcoat_normal_texture.uv_set), "the clearcoat normal texture uses",
                    "clearcoat normal map has no effect"};
        if (anisotropic) return {0, "anisotropy takes its tangents from", "anisotropy has no direction"};
        return {};
    }

    void check_memory() const {
        // What the import will hold at its peak: the parsed buffers plus the Scene it builds.
        size_t total = 0;
        for (const tinygltf::Buffer& b : m_model.buffers) total += b.data.size();
        for (const ImageCapture& c : m_loader.images) total += c.encoded.size();
        for (const MeshKey& k : m_requests) {
            const tinygltf::Primitive& p = m_model.meshes[size_t(k.mesh)].primitives[size_t(k.primitive)];
            const size_t verts = m_model.accessors[size_t(p.attributes.at("POSITION"))].count;
            size_t per_vertex = 2 * sizeof(Vec3f);  // positions, normals
            if (p.attributes.count("TANGENT") || tangent_need(p).uv >= 0) per_vertex += sizeof(Vec4f);
            if (p.attributes.count("TEXCOORD_0")) per_vertex += sizeof(Vec2f);
            if (p.attributes.count("TEXCOORD_1")) per_vertex += sizeof(Vec2f);
            if (p.attributes.count("COLOR_0")) per_vertex += sizeof(Vec4f);
            const size_t n = p.indices >= 0 ? m_model.accessors[size_t(p.indices)].count : verts;
            total += verts * per_vertex + (n + 3) * 3 * sizeof(uint32_t);  // fans/strips: up to 3 per element
        }
        total += m_scene.instances.size() * (sizeof(Instance) + 32);
        // Decoded textures: RGBA8 with mips (4/3) plus the decoder's own copy (up to 16-bit RGBA).
        for (const Texture& t : m_scene.textures) {
            if (!m_options.load_textures) break;
            int w = 0, h = 0;
            const std::pair<const uint8_t*, size_t> bytes = image_bytes(t.image);
            if (image_size_from_header(bytes.first, bytes.second, w, h)) total += decoded_image_bytes(w, h);
        }
        if (total > m_options.max_memory)
            fail("", "the scene needs about {} MiB, more than the limit of {} MiB (ImportOptions::max_memory)",
                 total >> 20, m_options.max_memory >> 20);
    }

    // ---- geometry -----------------------------------------------------------------------------
    /// Geometry of one primitive in object space (material and name set by the caller).
    Mesh build_geometry(const tinygltf::Primitive& p, const std::string& ptr, WarningLog& warnings) const {
        Mesh mesh;
        // Positions (finite: checked by validation).
        const AccessorData pos = accessor_data(m_model, p.attributes.at("POSITION"));
        mesh.positions.resize(pos.count);
        for_each_element(pos, [&](size_t i, const float* v) { mesh.positions[i] = {v[0], v[1], v[2]}; });
        const size_t nv = mesh.positions.size();

        // Triangles from TRIANGLES / TRIANGLE_STRIP / TRIANGLE_FAN (glTF 2.0 spec 3.7.2.1).
        std::vector<uint32_t> elements;
        if (p.indices >= 0) {
            const AccessorData ia = accessor_data(m_model, p.indices);
            elements.resize(ia.count);
            for_each_index(ia, [&](size_t i, uint32_t v) { elements[i] = v; });
        } else {
            elements.resize(nv);
            std::iota(elements.begin(), elements.end(), 0u);
        }
        const size_t n = elements.size();
        const size_t tris = triangle_count_for_mode(p.mode, n);
        mesh.indices.resize(tris * 3);
        uint32_t* out = mesh.indices.data();
        for (size_t t = 0; t < tris; ++t, out += 3) {
            if (p.mode == TINYGLTF_MODE_TRIANGLES) {
                out[0] = elements[3 * t], out[1] = elements[3 * t + 1], out[2] = elements[3 * t + 2];
            } else if (p.mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
                // {v_i, v_(i+1+i%2), v_(i+2-i%2)}: every other triangle reversed to keep the winding.
                out[0] = elements[t], out[1] = elements[t + 1 + t % 2], out[2] = elements[t + 2 - t % 2];
            } else {
                out[0] = elements[t + 1], out[1] = elements[t + 2], out[2] = elements[0];
            }
        }

        // Normals: read, normalize, and replace zero / non-finite ones by generated smooth normals.
        bool need_generated = true;
        std::vector<char> bad;
        if (auto it = p.attributes.find("NORMAL"); it != p.attributes.end()) {
            mesh.normals.resize(nv);
            bad.assign(nv, 0);
            need_generated = false;
            for_each_element(accessor_data(m_model, it->second), [&](size_t i, const float* v) {
                const Vec3f nn{v[0], v[1], v[2]};
                const float len = length(nn);
                const bool ok = std::isfinite(len) && len > 1e-20f;
                bad[i] = !ok;
                mesh.normals[i] = ok ? nn / len : Vec3f(0.f);
            });
            need_generated = std::find(bad.begin(), bad.end(), 1) != bad.end();
            if (need_generated)
                warnings.add("bad-normals",
                               fmt::format("{}: zero or non-finite normals replaced by generated ones", ptr));
        }
        if (need_generated) {
            const std::vector<Vec3f> smooth = smooth_normals(mesh);
            if (mesh.normals.empty())
                mesh.normals = smooth;
            else
                for (size_t i = 0; i < nv; ++i)
                    if (bad[i]) mesh.normals[i] = smooth[i];
        }

        // Texture coordinates and vertex colors.
        auto read_uv = [&](const char* name, std::vector<Vec2f>& dst) {
            auto it = p.attributes.find(name);
            if (it == p.attributes.end()) return;
            dst.resize(nv);
            for_each_element(accessor_data(m_model, it->second), [&](size_t i, const float* v) {
                dst[i] = {v[0], v[1]};
            });
        };
        read_uv("TEXCOORD_0", mesh.uv0);
        read_uv("TEXCOORD_1", mesh.uv1);
        if (auto it = p.attributes.find("COLOR_0"); it != p.attributes.end()) {
            const AccessorData c = accessor_data(m_model, it->second);
            mesh.colors.resize(nv);
            for_each_element(c, [&](size_t i, const float* v) {
                mesh.colors[i] = {v[0], v[1], v[2], c.components == 4 ? v[3] : 1.f};
            });
        }

        // Tangents: read when present, generated when the material needs them (tangent_need).
        const TangentNeed need = tangent_need(p);
        const int tangent_uv = need.uv;
        if (auto it = p.attributes.find("TANGENT"); it != p.attributes.end()) {
            mesh.tangents.resize(nv);
            bool any_bad = false;
            for_each_element(accessor_data(m_model, it->second), [&](size_t i, const float* v) {
                const Vec3f t{v[0], v[1], v[2]};
                const float len = length(t);
                const bool ok = std::isfinite(len) && len > 1e-20f;
                any_bad |= !ok;
                mesh.tangents[i] = ok ? Vec4f(t / len, v[3] < 0.f ? -1.f : 1.f) : Vec4f(0.f);
            });
            if (any_bad) {
                for (size_t i = 0; i < nv; ++i)
                    if (mesh.tangents[i].xyz() == Vec3f(0.f))
                        mesh.tangents[i] = Vec4f(any_perpendicular(mesh.normals[i]), 1.f);
                warnings.add("bad-tangents", fmt::format("{}: zero or non-finite tangents replaced", ptr));
            }
        } else if (tangent_uv >= 0) {
            const std::vector<Vec2f>& uv = tangent_uv == 0 ? mesh.uv0 : mesh.uv1;
            if (uv.empty())
                warnings.add(std::string("tangent-no-uv:") + need.reason,
                             fmt::format("{}: {} TEXCOORD_{}, which the primitive lacks: no tangents, {}", ptr,
                                         need.reason, tangent_uv, need.effect));
            else
                mesh.tangents = generate_tangents(mesh, uv);
        }
        return mesh;
    }

    static Vec3f any_perpendicular(const Vec3f& n) {
        const Vec3f a = std::fabs(n.x) < 0.9f ? Vec3f(1.f, 0.f, 0.f) : Vec3f(0.f, 1.f, 0.f);
        return normalize(cross(a, n));
    }

    /// Per-vertex tangents from UV gradients (Lengyel 2001, "Computing Tangent Space Basis
    /// Vectors for an Arbitrary Mesh"), accumulated over triangles, Gram-Schmidt against the
    /// normal. The sign w makes cross(N, T) * w point along -dP/dv: glTF's v runs down the image
    /// while a normal map's +Y is up (as MikkTSpace tangents exported from v-up tools do).
    static std::vector<Vec4f> generate_tangents(const Mesh& mesh, const std::vector<Vec2f>& uv) {
        const size_t nv = mesh.positions.size();
        std::vector<Vec3f> tan(nv, Vec3f(0.f)), bit(nv, Vec3f(0.f));
        for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
            const uint32_t i0 = mesh.indices[t], i1 = mesh.indices[t + 1], i2 = mesh.indices[t + 2];
            const Vec3f e1 = mesh.positions[i1] - mesh.positions[i0], e2 = mesh.positions[i2] - mesh.positions[i0];
            const Vec2f d1 = uv[i1] - uv[i0], d2 = uv[i2] - uv[i0];
            const float det = d1.x * d2.y - d2.x * d1.y;
            if (!(std::fabs(det) > 1e-20f) || !std::isfinite(det)) continue;  // degenerate UV triangle
            const float r = 1.f / det;
            const Vec3f sdir = (e1 * d2.y - e2 * d1.y) * r;  // dP/du
            const Vec3f tdir = (e2 * d1.x - e1 * d2.x) * r;  // dP/dv
            if (!is_finite(sdir) || !is_finite(tdir)) continue;
            for (uint32_t i : {i0, i1, i2}) tan[i] += sdir, bit[i] += tdir;
        }
        std::vector<Vec4f> out(nv);
        for (size_t i = 0; i < nv; ++i) {
            const Vec3f& n = mesh.normals[i];
            Vec3f t = normalize(tan[i] - n * dot(n, tan[i]));
            if (!(length(t) > 0.5f)) t = any_perpendicular(n);
            const float w = dot(cross(n, t), -bit[i]) < 0.f ? -1.f : 1.f;
            out[i] = Vec4f(t, w);
        }
        return out;
    }

    /// Geometry shared by every primitive with the same attribute and index accessors and mode
    /// (MetalRoughSpheres: 98 materials on one sphere) is decoded once.
    struct GeometryKey {
        const std::map<std::string, int>* attributes;  ///< the primitive's, in m_model
        int indices, mode, tangent_uv;
        bool operator==(const GeometryKey& o) const {
            return indices == o.indices && mode == o.mode && tangent_uv == o.tangent_uv && *attributes == *o.attributes;
        }
    };
    struct GeometryKeyHash {
        size_t operator()(const GeometryKey& k) const {
            // Equal maps list equal accessors in the same (name) order: the names need no hashing.
            uint64_t h = (uint64_t(uint32_t(k.indices)) << 32) ^ (uint64_t(uint32_t(k.mode)) << 8) ^ uint32_t(k.tangent_uv);
            for (const auto& entry : *k.attributes) h = (h ^ uint32_t(entry.second)) * 0x100000001b3ull;
            return size_t(h ^ (h >> 29));
        }
    };

    void build_meshes() {
        // Which request decodes its geometry and which copies an earlier request's.
        const size_t n = m_requests.size();
        std::unordered_map<GeometryKey, uint32_t, GeometryKeyHash> decoded;  // geometry -> first request
        decoded.reserve(n);
        std::vector<uint32_t> source(n);  // request -> the request whose geometry it uses
        std::vector<uint32_t> unique;     // requests that decode, in order
        for (size_t i = 0; i < n; ++i) {
            const tinygltf::Primitive& p = primitive(m_requests[i]);
            const int tangent_uv = tangent_need(p).uv;
            if (m_requests[i].node >= 0) {  // deformed by its node's pose: geometry of its own
                source[i] = uint32_t(i);
                unique.push_back(uint32_t(i));
                continue;
            }
            const auto [it, inserted] = decoded.emplace(GeometryKey{&p.attributes, p.indices, p.mode, tangent_uv},
                                                        uint32_t(i));
            source[i] = it->second;
            if (inserted) unique.push_back(uint32_t(i));
        }

        // Decode on all cores; each geometry's warnings are kept apart and appended below in
        // request order, so the log is the same for any thread count.
        std::vector<Mesh> built(unique.size());
        std::vector<WarningLog> logs(unique.size());
        m_rest.assign(n, Mesh{});
        m_bindings.assign(n, SkinBinding{});
        tbb::parallel_for(size_t(0), unique.size(), [&](size_t u) {
            const MeshKey& k = m_requests[unique[u]];
            built[u] = build_geometry(primitive(k), mesh_pointer(k), logs[u]);
            if (k.node >= 0 && deforming(m_model, k.node, m_pose)) {  // kept for repose()
                m_rest[unique[u]] = built[u];
                m_bindings[unique[u]] = skin_binding(m_model, m_path, k.node, k.primitive, built[u].positions.size());
                finish_geometry(k, built[u], logs[u], true, &m_bindings[unique[u]]);
                return;
            }
            finish_geometry(k, built[u], logs[u]);
        });

        m_scene.meshes.reserve(n);
        for (size_t i = 0, u = 0; i < n; ++i) {
            const MeshKey& k = m_requests[i];
            const tinygltf::Mesh& gm = m_model.meshes[size_t(k.mesh)];
            Mesh mesh;
            if (source[i] == i) {
                m_warnings.append(logs[u]);
                mesh = std::move(built[u++]);
            } else {
                mesh = m_scene.meshes[source[i]];
                if (m_requests[source[i]].mirrored != k.mirrored) mirror(mesh);
            }
            mesh.name = fmt::format("{}/{}", gm.name.empty() ? fmt::format("mesh {}", k.mesh) : gm.name, k.primitive);
            if (k.mirrored) mesh.name += " (mirrored)";
            const int material = gm.primitives[size_t(k.primitive)].material;
            mesh.material = material >= 0 ? uint32_t(material) : default_material();
            mesh.deforming = !m_rest[i].positions.empty();
            m_scene.meshes.push_back(std::move(mesh));
        }
        if (m_scene.materials.empty()) default_material();
    }

    const tinygltf::Primitive& primitive(const MeshKey& k) const {
        return m_model.meshes[size_t(k.mesh)].primitives[size_t(k.primitive)];
    }

    static std::string mesh_pointer(const MeshKey& k) {
        return fmt::format("/meshes/{}/primitives/{}", k.mesh, k.primitive);
    }

    /// A primitive's decoded geometry made what the Scene holds: deformed to the pose (its node's
    /// skin and morph weights; normals computed when the file has none), its numbers sanitised, its
    /// winding mirrored for a mirroring transform.
    /// `winding` false: the indices are left as they are (repose() borrows the rest pose's).
    void finish_geometry(const MeshKey& k, Mesh& mesh, WarningLog& log, bool winding = true,
                         const SkinBinding* binding = nullptr) const {
        if (k.node >= 0) {
            deform_mesh(mesh, m_model, m_path, k.node, k.primitive, m_pose, binding);
            if (!primitive(k).attributes.count("NORMAL")) mesh.normals = smooth_normals(mesh);
        }
        report_mesh_numbers(sanitize_mesh_numbers(mesh), mesh_pointer(k), log);
        if (k.mirrored) mirror(mesh, winding);
    }

    /// The copy of a mesh for transforms with a negative determinant: glTF says such a transform
    /// turns the winding clockwise, so swapping two indices restores counter-clockwise fronts.
    /// Tangent w flips too, so cross(N, T) * w computed in world space stays the transformed
    /// bitangent.
    static void mirror(Mesh& mesh, bool winding = true) {
        if (winding)
            for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) std::swap(mesh.indices[t + 1], mesh.indices[t + 2]);
        for (Vec4f& t : mesh.tangents) t.w = -t.w;
    }

    // ---- textures -----------------------------------------------------------------------------
    /// Encoded bytes of image `i` (PNG/JPEG); valid after validation.
    std::pair<const uint8_t*, size_t> image_bytes(int i) const {
        const tinygltf::Image& img = m_model.images[size_t(i)];
        const ImageCapture& c = m_loader.images[size_t(i)];
        if (c.from_buffer_view && img.bufferView >= 0) {
            const tinygltf::BufferView& bv = m_model.bufferViews[size_t(img.bufferView)];
            return {m_model.buffers[size_t(bv.buffer)].data.data() + bv.byteOffset, bv.byteLength};
        }
        return {c.encoded.data(), c.encoded.size()};
    }

    /// Decodes image `i` to 8-bit RGBA (stb_image through tinygltf; 16-bit images rounded to 8)
    /// after checking the dimensions its header declares.
    MipLevel decode_image(int i) const {
        const std::pair<const uint8_t*, size_t> bytes = image_bytes(i);
        const tinygltf::Image& src = m_model.images[size_t(i)];
        const std::string label = !src.uri.empty()    ? shorten_data_uris(src.uri)
                                  : !src.name.empty() ? src.name
                                                      : fmt::format("image {}", i);
        return decode_image_rgba8(bytes.first, bytes.second, m_options.max_memory,
                                  file_loc(m_path, fmt::format("/images/{}", i)), label);
    }

    /// Each image decoded once; then each texture's MIP chain. Both in parallel (images, textures)
    /// when there is enough work to share. A bad image is reported as the serial loop would: the
    /// first one in the textures' order.
    void decode_textures() {
        if (!m_options.load_textures) return;
        std::vector<int> unique;  // images in the order the textures first use them
        std::unordered_map<int, size_t> slot;
        for (const Texture& t : m_scene.textures)
            if (slot.emplace(t.image, unique.size()).second) unique.push_back(t.image);
        // In parallel only where there is work to share: threads cost more than they save on
        // small images (the fuzzers' inputs ran 3x slower under ASan with tasks for every image).
        constexpr size_t kParallelBytes = size_t(256) << 10;  // encoded bytes, all images together
        size_t encoded = 0;
        for (const int i : unique) encoded += image_bytes(i).second;
        std::vector<MipLevel> images(unique.size());
        if (unique.size() > 1 && encoded >= kParallelBytes) {
            std::vector<std::exception_ptr> failed(unique.size());
            tbb::parallel_for(size_t(0), unique.size(), [&](size_t u) {
                try {
                    images[u] = decode_image(unique[u]);
                } catch (...) {
                    failed[u] = std::current_exception();
                }
            });
            for (const std::exception_ptr& e : failed)
                if (e) std::rethrow_exception(e);
        } else {
            for (size_t u = 0; u < unique.size(); ++u) images[u] = decode_image(unique[u]);  // throws at the first
        }
        auto build = [&](size_t i) {
            Texture& t = m_scene.textures[i];
            t.levels.assign(1, images[slot.at(t.image)]);
            if (t.use_mips) build_mip_levels(t);
        };
        size_t texels = 0;  // of the base levels whose chains are built
        for (const Texture& t : m_scene.textures)
            if (t.use_mips) texels += images[slot.at(t.image)].texels.size() / 4;
        if (m_scene.textures.size() > 1 && texels >= (size_t(1) << 18))
            tbb::parallel_for(size_t(0), m_scene.textures.size(), build);
        else
            for (size_t i = 0; i < m_scene.textures.size(); ++i) build(i);
    }

    // ---- defaults -----------------------------------------------------------------------------
    void add_defaults() {
        if (m_scene.materials.empty()) default_material();
        add_scene_defaults(m_scene, m_options, m_warnings);  // camera, then light (scene_defaults.cpp)
    }

    const std::string m_path;
    ImportOptions m_options;            ///< its time changes with repose()
    std::string m_base_dir;
    UriPolicy m_uri_policy;
    tinygltf::Model m_model;
    LoaderState m_loader;
    Scene m_scene;
    WarningLog m_warnings;
    std::vector<int> m_animations;  ///< the animations posed (--animation)
    GltfPose m_pose;                ///< every node at the chosen time
    std::map<std::pair<int, bool>, int32_t> m_texture_map;  ///< (glTF texture, sRGB) -> Scene texture
    std::map<MeshKey, uint32_t> m_mesh_map;                 ///< -> Scene mesh
    std::vector<MeshKey> m_requests;                        ///< Scene mesh -> what it is built from
    std::vector<Mesh> m_rest;       ///< per Scene mesh: a deforming one's geometry before the pose (else empty)
    std::vector<SkinBinding> m_bindings;  ///< per Scene mesh: a deforming one's skin (else empty), read once
    int m_default_material = -1;
};

}  // namespace

namespace {

class GltfAnimator final : public SceneAnimator {
public:
    GltfAnimator(std::string path, ImportOptions options, std::unique_ptr<GltfImporter> importer)
        : m_path(std::move(path)), m_options(std::move(options)), m_importer(std::move(importer)) {}

    SceneUpdate pose(Scene& scene, double time) override {
        if (std::optional<SceneUpdate> u = m_importer->repose(scene, time)) return *u;
        log_debug("{}: the node graph changes its structure at {} s: loaded again", m_path, time);
        ImportOptions at = m_options;
        at.time = time;
        AnimatedScene fresh = load_animated_scene(m_path, at);
        scene = std::move(fresh.scene);
        m_importer = std::move(dynamic_cast<GltfAnimator&>(*fresh.animator).m_importer);
        SceneUpdate u;
        u.reloaded = true;
        return u;
    }

private:
    std::string m_path;
    ImportOptions m_options;
    std::unique_ptr<GltfImporter> m_importer;
};

}  // namespace

AnimatedScene import_gltf_animated(const std::string& path, const ImportOptions& options) {
    const FileBytes bytes = read_file(path, options.max_memory);
    auto importer = std::make_unique<GltfImporter>(path, options);
    AnimatedScene a;
    a.scene = importer->run(bytes.bytes());
    a.animator = std::make_unique<GltfAnimator>(path, options, std::move(importer));
    return a;
}

Scene import_gltf(const std::string& path, const ImportOptions& options) {
    const FileBytes bytes = read_file(path, options.max_memory);
    return GltfImporter(path, options).run(bytes.bytes());
}

Scene import_gltf_memory(std::span<const uint8_t> bytes, const std::string& path, const ImportOptions& options) {
    return GltfImporter(path, options).run(bytes);
}

}  // namespace whitted
