// JSON parsing with locations for the scene file (docs/scene-format.md "Errors").

#include "importers/scene_file_json.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <unordered_set>

#include <fmt/format.h>

namespace whitted::scene_file {

namespace {

/// Thrown from the parser callback (duplicate key, nesting): carries the message and pointer.
struct CallbackError {
    std::string message;
    std::string pointer;
};

/// The parser callback's view of where it is: one frame per open object/array.
struct Frame {
    bool is_object = false;
    std::string key;                        ///< object: the current member
    long index = -1;                        ///< array: the current element
    std::unordered_set<std::string> keys;   ///< object: members seen so far
};

std::string frames_pointer(const std::vector<Frame>& frames) {
    std::string p;
    for (const Frame& f : frames) p += "/" + (f.is_object ? pointer_token(f.key) : std::to_string(std::max(0L, f.index)));
    return p;
}

bool is_ws(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

size_t skip_ws(std::string_view t, size_t i) {
    while (i < t.size() && is_ws(t[i])) ++i;
    return i;
}

/// `i` at an opening quote: the index after the closing one.
size_t skip_string(std::string_view t, size_t i) {
    for (++i; i < t.size(); ++i) {
        if (t[i] == '\\') ++i;
        else if (t[i] == '"') return i + 1;
    }
    return t.size();
}

/// `i` at the first character of a value: the index after it.
size_t skip_value(std::string_view t, size_t i) {
    if (i >= t.size()) return i;
    if (t[i] == '"') return skip_string(t, i);
    if (t[i] == '{' || t[i] == '[') {
        size_t depth = 0;
        while (i < t.size()) {
            const char c = t[i];
            if (c == '"') {
                i = skip_string(t, i);
                continue;
            }
            if (c == '{' || c == '[') ++depth;
            if (c == '}' || c == ']') {
                if (--depth == 0) return i + 1;
            }
            ++i;
        }
        return i;
    }
    while (i < t.size() && !is_ws(t[i]) && t[i] != ',' && t[i] != ']' && t[i] != '}') ++i;
    return i;
}

/// The decoded text of the JSON string starting at `i` (a quote).
std::string string_at(std::string_view t, size_t i) {
    const size_t end = skip_string(t, i);
    const std::string_view raw = t.substr(i, end - i);
    if (raw.find('\\') == std::string_view::npos) return std::string(raw.substr(1, raw.size() >= 2 ? raw.size() - 2 : 0));
    try {
        return Json::parse(raw).get<std::string>();
    } catch (const std::exception&) {
        return std::string(raw);
    }
}

std::vector<std::string> pointer_tokens(std::string_view pointer) {
    std::vector<std::string> tokens;
    size_t i = 0;
    while (i < pointer.size() && pointer[i] == '/') {
        size_t j = pointer.find('/', i + 1);
        if (j == std::string_view::npos) j = pointer.size();
        std::string tok;
        for (size_t k = i + 1; k < j; ++k) {
            if (pointer[k] == '~' && k + 1 < j) {
                tok += pointer[k + 1] == '1' ? '/' : '~';
                ++k;
            } else {
                tok += pointer[k];
            }
        }
        tokens.push_back(std::move(tok));
        i = j;
    }
    return tokens;
}

/// Offset of the first number token whose value is outside the double range, or npos.
size_t find_overflowing_number(std::string_view t) {
    for (size_t i = 0; i < t.size();) {
        const char c = t[i];
        if (c == '"') {
            i = skip_string(t, i);
        } else if (c == '-' || (c >= '0' && c <= '9')) {
            size_t j = i;
            while (j < t.size() && (std::isdigit((unsigned char)t[j]) || t[j] == '-' || t[j] == '+' || t[j] == '.' ||
                                    t[j] == 'e' || t[j] == 'E'))
                ++j;
            const std::string token(t.substr(i, j - i));
            if (!std::isfinite(std::strtod(token.c_str(), nullptr))) return i;
            i = j;
        } else {
            ++i;
        }
    }
    return std::string::npos;
}

/// nlohmann's parse_error text without its "[json.exception...] parse error at line L, column C: "
/// prefix (the location is reported in whitted's own format).
std::string strip_nlohmann_prefix(const std::string& what) {
    std::string s = what;
    if (const size_t p = s.find("] "); p != std::string::npos && s.rfind("[json.exception", 0) == 0) s = s.substr(p + 2);
    if (s.rfind("parse error", 0) == 0) {
        if (const size_t p = s.find(": "); p != std::string::npos) s = s.substr(p + 2);
    }
    // Control characters (a raw byte quoted from the file) must not reach the terminal.
    for (char& c : s)
        if ((unsigned char)c < 0x20 || c == 0x7f) c = '?';
    return s;
}

[[noreturn]] void fail_at(const std::string& path, std::string_view text, size_t offset, const std::string& pointer,
                          const std::string& message) {
    FileLoc loc;
    loc.file = path;
    loc.pointer = pointer;
    std::tie(loc.line, loc.column) = line_column(text, std::min(offset, text.size()));
    throw Error(loc, message);
}

}  // namespace

std::string pointer_token(std::string_view key) {
    std::string s;
    for (char c : key) {
        if (c == '~') s += "~0";
        else if (c == '/') s += "~1";
        else s += c;
    }
    return s;
}

std::pair<int, int> line_column(std::string_view text, size_t offset) {
    offset = std::min(offset, text.size());
    int line = 1;
    size_t line_start = 0;
    for (size_t i = 0; i < offset; ++i)
        if (text[i] == '\n') ++line, line_start = i + 1;
    int column = 1;
    for (size_t i = line_start; i < offset; ++i)
        if ((static_cast<unsigned char>(text[i]) & 0xC0) != 0x80) ++column;  // UTF-8 continuation bytes
    return {line, column};
}

TextPosition find_pointer(std::string_view t, std::string_view pointer) {
    TextPosition pos;
    pos.value = skip_ws(t, 0);
    pos.exact = true;
    for (const std::string& token : pointer_tokens(pointer)) {
        const size_t at = pos.value;
        if (at >= t.size() || (t[at] != '{' && t[at] != '[')) return {pos.value, pos.key, false};
        size_t i = skip_ws(t, at + 1);
        size_t found = std::string::npos, found_key = std::string::npos;
        if (t[at] == '{') {
            // Members: the last one named `token` (nlohmann keeps the last of duplicates).
            while (i < t.size() && t[i] == '"') {
                const size_t key = i;
                const std::string name = string_at(t, i);
                i = skip_ws(t, skip_string(t, i));
                if (i < t.size() && t[i] == ':') i = skip_ws(t, i + 1);
                if (name == token) found = i, found_key = key;
                i = skip_ws(t, skip_value(t, i));
                if (i < t.size() && t[i] == ',') i = skip_ws(t, i + 1);
            }
        } else {
            char* end = nullptr;
            const unsigned long want = std::strtoul(token.c_str(), &end, 10);
            if (token.empty() || *end != '\0') return {pos.value, pos.key, false};
            for (unsigned long k = 0; i < t.size() && t[i] != ']'; ++k) {
                if (k == want) {
                    found = i;
                    break;
                }
                i = skip_ws(t, skip_value(t, i));
                if (i < t.size() && t[i] == ',') i = skip_ws(t, i + 1);
            }
        }
        if (found == std::string::npos) return {pos.value, pos.key, false};
        pos.value = found;
        pos.key = found_key;
    }
    return pos;
}

FileLoc locate(const JsonDocument& doc, const std::string& pointer, bool at_key) {
    FileLoc loc;
    loc.file = doc.path;
    loc.pointer = pointer;
    const TextPosition p = find_pointer(doc.text, pointer);
    const size_t offset = at_key && p.exact && p.key != std::string::npos ? p.key : p.value;
    std::tie(loc.line, loc.column) = line_column(doc.text, offset);
    return loc;
}

namespace {

/// The SAX handler of parse_json_document and parse_object: builds the value (nlohmann's DOM
/// builder) and tracks the pointer of what is being parsed, refuses duplicate keys and deep
/// nesting, and records the order of /materials and /textures (nlohmann::json sorts keys). Not
/// Json::parse with a callback: its builder scans the parent container at the end of every
/// object, quadratic in the length of /objects.
///
/// With `stream_objects`, the elements of the root's /objects array are checked for syntax only
/// and left out of the value (they are parsed one at a time by parse_object, so a file of a
/// million spheres never holds a million-element DOM).
struct Sax {
    nlohmann::detail::json_sax_dom_parser<Json> dom;
    JsonDocument* doc = nullptr;      ///< receives the material/texture order (the whole file)
    std::string base;                 ///< pointer of the value being parsed ("" or /objects/i)
    size_t base_depth = 0;            ///< its nesting depth in the file
    bool stream_objects = false;
    std::vector<Frame> frames;
    size_t skip_from = SIZE_MAX;      ///< frames.size() of the /objects frame: deeper is skipped

    bool skipping() const { return frames.size() >= skip_from; }
    std::string pointer() const { return base + frames_pointer(frames); }
    void value() {
        if (!frames.empty() && !frames.back().is_object) ++frames.back().index;
    }
    void open(bool is_object) {
        value();
        if (base_depth + frames.size() >= size_t(kMaxJsonDepth))
            throw CallbackError{fmt::format("invalid JSON: arrays/objects nested deeper than {} levels", kMaxJsonDepth),
                                pointer()};
        Frame f;
        f.is_object = is_object;
        frames.push_back(std::move(f));
    }
    /// After a container closed: whether the builder sees it.
    bool close() {
        if (!frames.empty()) frames.pop_back();
        if (frames.size() + 1 == skip_from) skip_from = SIZE_MAX;  // /objects itself closed
        return !skipping();
    }
    bool null() { return value(), skipping() || dom.null(); }
    bool boolean(bool v) { return value(), skipping() || dom.boolean(v); }
    bool number_integer(Json::number_integer_t v) { return value(), skipping() || dom.number_integer(v); }
    bool number_unsigned(Json::number_unsigned_t v) { return value(), skipping() || dom.number_unsigned(v); }
    bool number_float(Json::number_float_t v, const Json::string_t& s) {
        return value(), skipping() || dom.number_float(v, s);
    }
    bool string(Json::string_t& v) { return value(), skipping() || dom.string(v); }
    bool binary(Json::binary_t& v) { return value(), skipping() || dom.binary(v); }
    bool start_object(size_t n) {
        const bool skip = skipping();
        open(true);
        return skip || dom.start_object(n);
    }
    bool start_array(size_t n) {
        const bool skip = skipping();
        open(false);
        if (stream_objects && frames.size() == 2 && frames[0].is_object && frames[0].key == "objects") {
            skip_from = 2;
            doc->objects_streamed = true;
        }
        return skip || dom.start_array(n);
    }
    bool end_object() { return !close() || dom.end_object(); }
    bool end_array() { return !close() || dom.end_array(); }
    bool key(Json::string_t& k) {
        Frame& f = frames.back();
        f.key = k;
        if (skipping()) return true;  // checked when parse_object reads the element
        if (!f.keys.insert(f.key).second)
            throw CallbackError{fmt::format("duplicate key '{}' (each key may appear once per object)", f.key),
                                pointer()};
        if (doc && frames.size() == 2 && frames[1].is_object && frames[0].is_object) {
            if (frames[0].key == "materials") doc->material_order.push_back(f.key);
            if (frames[0].key == "textures") doc->texture_order.push_back(f.key);
        }
        return dom.key(k);
    }
    template <class Exception>
    bool parse_error(size_t at, const std::string& token, const Exception& e) {
        return dom.parse_error(at, token, e);
    }
};

/// [begin, end) offsets of the elements of the array at `at` in valid JSON `t`.
std::vector<std::pair<size_t, size_t>> element_spans(std::string_view t, size_t at) {
    std::vector<std::pair<size_t, size_t>> spans;
    size_t i = skip_ws(t, at + 1);
    while (i < t.size() && t[i] != ']') {
        const size_t end = skip_value(t, i);
        spans.emplace_back(i, end);
        i = skip_ws(t, end);
        if (i < t.size() && t[i] == ',') i = skip_ws(t, i + 1);
    }
    return spans;
}

}  // namespace

JsonDocument parse_json_document(std::string text, const std::string& path) {
    JsonDocument doc;
    doc.path = path;
    doc.text = std::move(text);
    const std::string_view t = doc.text;
    if (t.size() >= 3 && (unsigned char)t[0] == 0xEF && (unsigned char)t[1] == 0xBB && (unsigned char)t[2] == 0xBF)
        fail_at(path, t, 0, "", "invalid JSON: the file starts with a UTF-8 byte order mark (save it without one)");

    // The handler (above) builds the document and checks it as it goes.
    try {
        Sax sax{nlohmann::detail::json_sax_dom_parser<Json>(doc.root), &doc, "", 0, true, {}};
        Json::sax_parse(doc.text, &sax);
        if (doc.objects_streamed) doc.objects = element_spans(t, find_pointer(t, "/objects").value);
    } catch (const CallbackError& e) {
        // The pointer is known; the offset of a duplicate key is the last member of that name.
        const TextPosition p = find_pointer(t, e.pointer);
        fail_at(path, t, p.key != std::string::npos ? p.key : p.value, e.pointer, e.message);
    } catch (const Json::parse_error& e) {
        // e.byte: 1-based index of the last character read.
        fail_at(path, t, e.byte > 0 ? size_t(e.byte - 1) : 0, "", "invalid JSON: " + strip_nlohmann_prefix(e.what()));
    } catch (const Json::out_of_range& e) {
        const size_t at = find_overflowing_number(t);
        fail_at(path, t, at == std::string::npos ? 0 : at, "",
                "invalid number: " + strip_nlohmann_prefix(e.what()) + " (outside the range of a double)");
    } catch (const std::bad_alloc&) {
        throw Error(FileLoc{path, "", 0, 0}, "out of memory while parsing the JSON");
    }
    return doc;
}

Json parse_object(const JsonDocument& doc, size_t i) {
    const auto [begin, end] = doc.objects.at(i);
    Json value;
    try {
        Sax sax{nlohmann::detail::json_sax_dom_parser<Json>(value), nullptr, fmt::format("/objects/{}", i), 2, false, {}};
        Json::sax_parse(std::string_view(doc.text).substr(begin, end - begin), &sax);
    } catch (const CallbackError& e) {
        const TextPosition p = find_pointer(doc.text, e.pointer);
        fail_at(doc.path, doc.text, p.key != std::string::npos ? p.key : p.value, e.pointer, e.message);
    }
    // Syntax and numbers were checked when the whole file was parsed.
    return value;
}

namespace {

/// A plain JSON string at t[i] (a quote): its contents, i past the closing quote. False when it
/// has escapes (the general path decodes those).
bool scan_plain_string(std::string_view t, size_t& i, std::string_view& out) {
    if (i >= t.size() || t[i] != '"') return false;
    const size_t begin = ++i;
    while (i < t.size() && t[i] != '"') {
        if (t[i] == '\\') return false;
        ++i;
    }
    if (i >= t.size()) return false;
    out = t.substr(begin, i - begin);
    ++i;
    return true;
}

/// The characters of the JSON number at t[i] (valid JSON): [first, last), i past them, and
/// whether it is an integer (no fraction, no exponent). False for none or an overlong one.
bool number_token(std::string_view t, size_t& i, const char*& first, const char*& last, bool& integer) {
    const size_t begin = i;
    integer = true;
    while (i < t.size() && (std::isdigit(static_cast<unsigned char>(t[i])) || t[i] == '-' || t[i] == '+' ||
                            t[i] == '.' || t[i] == 'e' || t[i] == 'E')) {
        integer &= t[i] != '.' && t[i] != 'e' && t[i] != 'E';
        ++i;
    }
    if (i == begin || i - begin > 40) return false;
    first = t.data() + begin;
    last = t.data() + i;
    return true;
}

/// A JSON number at t[i], converted as nlohmann::json converts it (integers as 64-bit integers,
/// then to double; others with correct rounding). False when out of range (the general path
/// reports or rounds those).
bool scan_number(std::string_view t, size_t& i, double& out) {
    const char *first = nullptr, *last = nullptr;
    bool integer = true;
    if (!number_token(t, i, first, last, integer)) return false;
    if (integer) {
        long long v = 0;
        const auto r = std::from_chars(first, last, v);
        out = double(v);
        return r.ec == std::errc() && r.ptr == last;
    }
    const auto r = std::from_chars(first, last, out);
    return r.ec == std::errc() && r.ptr == last;
}

/// A JSON number at t[i] as nlohmann::json stores it: an integer as int64 (with a sign) or uint64,
/// anything else as a correctly rounded double. False when out of range (nlohmann then falls back
/// to a double, or the general path reports it).
bool scan_json_number(std::string_view t, size_t& i, Json& out) {
    const char *first = nullptr, *last = nullptr;
    bool integer = true;
    if (!number_token(t, i, first, last, integer)) return false;
    if (integer && *first == '-') {
        int64_t v = 0;
        const auto r = std::from_chars(first, last, v);
        if (r.ec != std::errc() || r.ptr != last) return false;
        out = v;
    } else if (integer) {
        uint64_t v = 0;
        const auto r = std::from_chars(first, last, v);
        if (r.ec != std::errc() || r.ptr != last) return false;
        out = v;
    } else {
        double v = 0;
        const auto r = std::from_chars(first, last, v);
        if (r.ec != std::errc() || r.ptr != last || !std::isfinite(v)) return false;
        out = v;
    }
    return true;
}

/// An array at t[i] of numbers, or (`nested`) of arrays of numbers; i past it.
bool scan_number_array(std::string_view t, size_t& i, Json& out, bool nested) {
    if (i >= t.size() || t[i] != '[') return false;
    out = Json::array();
    Json::array_t& a = out.get_ref<Json::array_t&>();
    i = skip_ws(t, i + 1);
    if (i < t.size() && t[i] == ']') {
        ++i;
        return true;
    }
    while (true) {
        Json v;
        if (i < t.size() && t[i] == '[') {
            if (!nested || !scan_number_array(t, i, v, false)) return false;
        } else if (!scan_json_number(t, i, v)) {
            return false;
        }
        a.push_back(std::move(v));
        i = skip_ws(t, i);
        if (i < t.size() && t[i] == ']') {
            ++i;
            return true;
        }
        if (i >= t.size() || t[i] != ',') return false;
        i = skip_ws(t, i + 1);
    }
}

/// The plain object at t[i] (a '{'): `member(key, i)` reads each member's value at t[i], leaving i
/// past it, and returns the member's bit (0: not one it reads). Returns the bits of the members
/// read, with i past the '}'; 0 when a member is not read or repeats, or a key has escapes.
template <class Member>
unsigned scan_members(std::string_view t, size_t& i, Member&& member) {
    if (i >= t.size() || t[i] != '{') return 0;
    unsigned seen = 0;
    i = skip_ws(t, i + 1);
    while (true) {
        std::string_view key;
        if (!scan_plain_string(t, i, key)) return 0;
        i = skip_ws(t, i);
        if (i >= t.size() || t[i] != ':') return 0;
        i = skip_ws(t, i + 1);
        const unsigned bit = member(key, i);
        if (bit == 0 || (seen & bit)) return 0;
        seen |= bit;
        i = skip_ws(t, i);
        if (i < t.size() && t[i] == '}') {
            ++i;
            return seen;
        }
        if (i >= t.size() || t[i] != ',') return 0;
        i = skip_ws(t, i + 1);
    }
}

}  // namespace

bool scan_mesh(std::string_view t, Json& out) {
    enum : unsigned { kType = 1, kPositions = 2, kIndices = 4, kNormals = 8, kMaterial = 16, kName = 32, kTransform = 64 };
    out = Json::object();
    size_t i = skip_ws(t, 0);
    const unsigned seen = scan_members(t, i, [&](std::string_view key, size_t& j) -> unsigned {
        unsigned bit = 0;
        Json value;
        if (key == "type" || key == "material" || key == "name") {
            std::string_view text;
            if (!scan_plain_string(t, j, text) || (key == "type" && text != "mesh")) return 0;
            value = std::string(text);
            bit = key == "type" ? kType : key == "material" ? kMaterial : kName;
        } else if (key == "positions" || key == "indices" || key == "normals") {
            if (!scan_number_array(t, j, value, true)) return 0;
            bit = key == "positions" ? kPositions : key == "indices" ? kIndices : kNormals;
        } else if (key == "transform") {  // exactly {"matrix": [numbers]}
            Json numbers;
            if (scan_members(t, j, [&](std::string_view k, size_t& m) -> unsigned {
                    return k == "matrix" && scan_number_array(t, m, numbers, false) ? 1u : 0u;
                }) == 0)
                return 0;
            value = Json::object();
            value["matrix"] = std::move(numbers);
            bit = kTransform;
        } else {
            return 0;
        }
        out[std::string(key)] = std::move(value);  // a repeated key makes scan_members fail: out is not used
        return bit;
    });
    return skip_ws(t, i) == t.size() && (seen & (kType | kPositions)) == (kType | kPositions);
}

bool scan_sphere(std::string_view t, SphereFields& f) {
    constexpr unsigned kType = 1, kCenter = 2, kRadius = 4, kMaterial = 8, kName = 16;
    size_t i = skip_ws(t, 0);
    const unsigned seen = scan_members(t, i, [&](std::string_view key, size_t& j) -> unsigned {
        if (key == "type") {
            std::string_view type;
            return scan_plain_string(t, j, type) && type == "sphere" ? kType : 0;
        }
        if (key == "center") {
            if (j >= t.size() || t[j] != '[') return 0;
            for (int k = 0; k < 3; ++k) {
                j = skip_ws(t, j + 1);
                if (!scan_number(t, j, f.center[k])) return 0;
                j = skip_ws(t, j);
                if (j >= t.size() || t[j] != (k < 2 ? ',' : ']')) return 0;
            }
            ++j;
            return kCenter;
        }
        if (key == "radius") return scan_number(t, j, f.radius) ? kRadius : 0;
        if (key == "material") return scan_plain_string(t, j, f.material) ? kMaterial : 0;
        if (key == "name") return scan_plain_string(t, j, f.name) ? kName : 0;
        return 0;
    });
    if (skip_ws(t, i) != t.size() || (seen & (kType | kCenter | kRadius)) != (kType | kCenter | kRadius)) return false;
    f.has_material = seen & kMaterial;
    f.has_name = seen & kName;
    return true;
}

std::string closest_match(std::string_view name, const std::vector<std::string>& candidates) {
    auto lower = [](std::string_view s) {
        std::string r(s);
        for (char& c : r) c = char(std::tolower((unsigned char)c));
        return r;
    };
    const std::string a = lower(name);
    if (a.size() > 64) return "";
    std::string best;
    size_t best_d = SIZE_MAX;
    for (const std::string& cand : candidates) {
        const std::string b = lower(cand);
        if (b.size() > 64) continue;
        // Optimal string alignment distance (Levenshtein plus adjacent transpositions).
        std::vector<std::vector<size_t>> d(a.size() + 1, std::vector<size_t>(b.size() + 1));
        for (size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
        for (size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
        for (size_t i = 1; i <= a.size(); ++i)
            for (size_t j = 1; j <= b.size(); ++j) {
                const size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
                d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
                if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
                    d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
            }
        const size_t dist = d[a.size()][b.size()];
        // Close enough to be a typo: about one edit per three characters, at least one; or another
        // form of the same word (a common stem of 4+ characters: "rotation" for "rotate").
        const size_t limit = std::max<size_t>(1, std::min(a.size(), b.size()) / 3);
        size_t stem = 0;
        while (stem < a.size() && stem < b.size() && a[stem] == b[stem]) ++stem;
        const bool same_word = stem >= 4 && 2 * stem >= std::max(a.size(), b.size());
        if ((dist <= limit || same_word) && dist < best_d) best = cand, best_d = dist;
    }
    return best;
}

std::string describe(const Json& v) {
    switch (v.type()) {
        case Json::value_t::null: return "null";
        case Json::value_t::boolean: return v.get<bool>() ? "true" : "false";
        case Json::value_t::string: {
            std::string s = v.get<std::string>();
            if (s.size() > 40) s = s.substr(0, 37) + "...";
            return Json(s).dump(-1, ' ', false, Json::error_handler_t::replace);
        }
        case Json::value_t::array: {
            const size_t n = v.size();
            return n == 0 ? "an empty array" : fmt::format("an array of {} element{}", n, n == 1 ? "" : "s");
        }
        case Json::value_t::object: return v.empty() ? "an empty object" : "an object";
        default: return v.dump();
    }
}

}  // namespace whitted::scene_file
