// JSON reading for the scene file with source locations (private to importers/): nlohmann::json
// parses; syntax errors, duplicate keys, excessive nesting and overflowing numbers become
// whitted::Error with line:column; a value's line:column is recovered from its JSON pointer by
// re-scanning the (valid) text, which is only done when reporting an error.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/error.h"

namespace whitted::scene_file {

using Json = nlohmann::json;

/// Deepest array/object nesting accepted (a scene file needs about 6).
constexpr int kMaxJsonDepth = 64;

struct JsonDocument {
    std::string path;                         ///< as given, for messages
    std::string text;                         ///< the file's bytes
    Json root;
    std::vector<std::string> material_order;  ///< keys of /materials in file order
    std::vector<std::string> texture_order;   ///< keys of /textures in file order
    /// When /objects is an array: its elements' [begin, end) offsets in `text`. They are not in
    /// `root` (whose /objects is an empty array): parse_object reads one at a time.
    bool objects_streamed = false;
    std::vector<std::pair<size_t, size_t>> objects;
};

/// Parses `text`. Throws whitted::Error at line:column for invalid JSON, a duplicate key, nesting
/// deeper than kMaxJsonDepth or a number out of double range.
JsonDocument parse_json_document(std::string text, const std::string& path);

/// Element `i` of /objects (objects_streamed), with the checks of parse_json_document (duplicate
/// keys, depth) located in the whole file.
Json parse_object(const JsonDocument& doc, size_t i);

/// A sphere element of /objects as scan_sphere reads it straight from the text.
struct SphereFields {
    double center[3] = {0, 0, 0};
    double radius = 0;
    std::string_view material, name;  ///< into the element's text (no escapes)
    bool has_material = false, has_name = false;
};

/// Whether element text `e` (valid JSON) is exactly a sphere object: the keys "type" (the string
/// "sphere"), "center" (3 numbers), "radius" (a number) and optionally "material" and "name"
/// (strings without escapes), each once, in any order; then `f` holds its values, numbers as
/// nlohmann::json reads them. False for anything else, which the general path reads (with its
/// checks and errors). The fast path of files with many spheres: no DOM per element.
bool scan_sphere(std::string_view e, SphereFields& f);

/// Whether element text `e` (valid JSON) is a mesh object of the plain form an exporter writes:
/// the keys "type" (the string "mesh"), "positions", optionally "indices" and "normals" (arrays of
/// numbers, flat or of arrays of numbers), "material" and "name" (strings without escapes) and
/// "transform" ({"matrix": [numbers]}), each once, in any order. Then `out` is the value
/// nlohmann::json would parse (the same number types and values), read without its lexer: the
/// fast path of files with large inline meshes, whose checks read_mesh still makes. False for
/// anything else, which parse_object reads.
bool scan_mesh(std::string_view e, Json& out);

/// Where the JSON pointer `pointer` is in valid JSON `text`: byte offsets of the value and (for
/// an object member) of its key; when a duplicate key occurs the last member counts (as in the
/// parsed value). When the pointer cannot be followed to the end, the deepest value reached is
/// returned with `exact` false.
struct TextPosition {
    size_t value = 0;
    size_t key = std::string::npos;
    bool exact = false;
};
TextPosition find_pointer(std::string_view text, std::string_view pointer);

/// 1-based line and column (in UTF-8 code points) of byte `offset`.
std::pair<int, int> line_column(std::string_view text, size_t offset);

/// FileLoc of `pointer` in the document, with line:column (of the member's key when `at_key`).
FileLoc locate(const JsonDocument& doc, const std::string& pointer, bool at_key = false);

/// A JSON pointer token for an object key ("~" -> "~0", "/" -> "~1").
std::string pointer_token(std::string_view key);

/// The candidate closest to `name` (case-insensitive optimal string alignment distance) when it
/// is close enough to be a likely typo, else "".
std::string closest_match(std::string_view name, const std::vector<std::string>& candidates);

/// A short description of a value for "expected ..., got ..." messages: "\"abc\"", "-1",
/// "true", "null", "an array of 2 elements", "an object".
std::string describe(const Json& value);

}  // namespace whitted::scene_file
