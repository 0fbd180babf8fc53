#include "integrator/render_settings.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "core/error.h"

namespace whitted {

namespace {

/// `length` scaled by the ratio `to / from`, rounded to the nearest pixel, at least 1.
int keep_aspect(int length, int to, int from) {
    return std::max(1, int(std::lround(double(length) * double(to) / double(from))));
}

/// The image size from the caller's width/height (0 = not set) and the file's.
void merge_image_size(const SceneRenderSettings& s, RenderSettings& rs, bool width_given, bool height_given) {
    const bool w = width_given && rs.width > 0, h = height_given && rs.height > 0;
    if (w && h) return;
    if (!w && !h) {
        if (s.width) rs.width = *s.width;
        if (s.height) rs.height = *s.height;
        return;
    }
    // One dimension given: the other keeps the file's aspect, or the camera's (0) without one.
    const bool file_aspect = s.width && s.height;
    if (w) rs.height = file_aspect ? keep_aspect(rs.width, *s.height, *s.width) : 0;
    else rs.width = file_aspect ? keep_aspect(rs.height, *s.width, *s.height) : 0;
}

}  // namespace

RenderSettings command_line_render_settings() {
    RenderSettings rs;
    rs.aa.mode = AaMode::Adaptive;
    rs.integrator.min_weight = 1.f / 255.f;
    rs.progress = true;
    return rs;
}

Color parse_color(const std::string& text, const char* what) {
    std::vector<float> v;
    std::stringstream in(text);
    std::string part;
    while (std::getline(in, part, ',')) {
        try {
            size_t used = 0;
            float f = std::stof(part, &used);
            if (used != part.size() || !std::isfinite(f)) throw std::invalid_argument(part);
            v.push_back(f);
        } catch (const std::exception&) {
            throw Error(fmt::format("{}: '{}' is not a color (expected r,g,b or a single value)", what, text));
        }
    }
    if (v.size() == 1) return Color(v[0]);
    if (v.size() == 3) return {v[0], v[1], v[2]};
    throw Error(fmt::format("{}: '{}' is not a color (expected r,g,b or a single value)", what, text));
}

int parse_env_occlusion(const std::string& text, const char* what) {
    if (text == "off") return 0;
    size_t used = 0;
    long v = -1;
    try {
        v = std::stol(text, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used != text.size() || text.empty() || v < 0 || v > kMaxEnvOcclusion)
        throw Error(fmt::format("{}: '{}' is not off or a number of directions from 0 to {}", what, text,
                                kMaxEnvOcclusion));
    return int(v);
}

AovSet parse_aovs(const std::vector<std::string>& names) {
    AovSet a;
    for (const std::string& n : names) {
        if (n == "depth" || n == "z") a.depth = true;
        else if (n == "normal" || n == "n") a.normal = true;
        else if (n == "albedo") a.albedo = true;
        else if (n == "primid" || n == "prim_id" || n == "primitive") a.prim_id = true;
        else if (n == "instid" || n == "inst_id" || n == "instance") a.inst_id = true;
        else if (n == "aa_samples" || n == "aasamples") a.aa_samples = true;
        else if (n == "all") a = AovSet{true, true, true, true, true, true};
        else
            throw Error(fmt::format(
                "--aov: unknown AOV '{}' (available: depth, normal, albedo, primid, instid, aa_samples, all)", n));
    }
    return a;
}

void apply_scene_settings(const SceneRenderSettings& s, RenderSettings& rs, const SettingGiven& given) {
    auto from_file = [&](std::string_view key) { return !given || !given(key); };
    merge_image_size(s, rs, !from_file("width"), !from_file("height"));
    if (s.camera && from_file("camera")) rs.camera = *s.camera;
    if (s.aa && from_file("aa")) rs.aa.mode = parse_aa_mode(*s.aa);
    if (s.aa_threshold && from_file("aa_threshold")) rs.aa.threshold = *s.aa_threshold;
    if (s.aa_depth && from_file("aa_depth")) rs.aa.depth = *s.aa_depth;
    if (s.spp && from_file("spp")) rs.aa.spp = *s.spp;
    if (s.max_depth && from_file("max_depth")) rs.integrator.max_depth = *s.max_depth;
    if (s.min_weight && from_file("min_weight")) rs.integrator.min_weight = *s.min_weight;
    if (s.background && from_file("background")) rs.integrator.background = *s.background;
    if (s.ambient && from_file("ambient")) rs.integrator.ambient = *s.ambient;
    if (s.exposure && from_file("exposure")) rs.exposure = std::exp2(*s.exposure);
    if (s.fresnel && from_file("fresnel")) rs.integrator.fresnel = *s.fresnel;
    // An environment's light replaces the constant ambient unless one was set; camera rays that
    // miss see it unless the caller set a background.
    if (s.ambient || !from_file("ambient")) rs.integrator.environment_ambient = false;
    if (!from_file("background")) rs.integrator.environment_visible = false;
}

SettingList describe_image_settings(const RenderSettings& rs) {
    auto num = [](double v) { return fmt::format("{:.9g}", v); };
    auto color = [&](const Color& c) { return fmt::format("{},{},{}", num(c.x), num(c.y), num(c.z)); };
    auto flag = [](bool b) { return std::string(b ? "on" : "off"); };
    const IntegratorSettings& in = rs.integrator;
    const AovSet& a = rs.aovs;
    SettingList out = {
        {"width", std::to_string(rs.width)},
        {"height", std::to_string(rs.height)},
        {"camera", std::to_string(rs.camera)},
        {"max_depth", std::to_string(in.max_depth)},
        {"background", color(in.background)},
        {"ambient", color(in.ambient)},
        {"fresnel", flag(in.fresnel)},
        {"min_weight", num(in.min_weight)},
        {"specialize", flag(in.specialize)},
        {"environment_ambient", flag(in.environment_ambient)},
        {"environment_visible", flag(in.environment_visible)},
        {"env_occlusion", std::to_string(in.env_occlusion)},
        {"mirror_cutoff", num(rs.mapping.mirror_roughness_cutoff)},
        {"max_exponent", num(rs.mapping.max_exponent)},
        {"refract_thin", flag(rs.mapping.refract_thin)},
        {"exposure", num(rs.exposure)},
        {"tile_size", std::to_string(rs.tile_size)},
        {"crop", rs.crop ? fmt::format("{},{},{},{}", rs.crop->x0, rs.crop->y0, rs.crop->x1, rs.crop->y1) : "none"},
        {"aovs", fmt::format("depth={} normal={} albedo={} prim_id={} inst_id={} aa_samples={}", flag(a.depth),
                             flag(a.normal), flag(a.albedo), flag(a.prim_id), flag(a.inst_id), flag(a.aa_samples))},
        {"aa", aa_mode_name(rs.aa.mode)},
        {"aa_threshold", num(rs.aa.threshold)},
        {"aa_depth", std::to_string(rs.aa.depth)},
        {"spp", std::to_string(rs.aa.spp)},
        {"filter", pixel_filter_name(rs.aa.filter)},
        {"texture_filter", texture_filter_name(rs.aa.texture_filter)},
        {"accel", rs.accel},
        {"robust", flag(rs.robust)},
    };
    return out;
}

}  // namespace whitted
