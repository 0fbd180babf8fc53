// `whitted info`: what the importer made of a file, one greppable record per line.

#include "importers/scene_report.h"
#include "shading/environment_map.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <vector>

#include <fmt/format.h>

#include "shading/material_mapping.h"
#include "shading/scene_analysis.h"

namespace whitted {

namespace {

std::string num(double v) {
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    if (std::isnan(v)) return "nan";
    if (v == 0) return "0";  // no "-0"
    return fmt::format("{:.6g}", v);
}

template <typename V>
std::string vec3(const V& v) {
    return fmt::format("({}, {}, {})", num(v.x), num(v.y), num(v.z));
}

std::string vec4(const Vec4f& v) { return fmt::format("({}, {}, {}, {})", num(v.x), num(v.y), num(v.z), num(v.w)); }

const char* yes_no(bool b) { return b ? "yes" : "no"; }

const char* light_type(LightType t) {
    switch (t) {
        case LightType::Point:
            return "point";
        case LightType::Spot:
            return "spot";
        default:
            return "directional";
    }
}

const char* attenuation_name(Attenuation a) {
    switch (a) {
        case Attenuation::InverseSquare:
            return "inverse-square";
        case Attenuation::Classic:
            return "classic";
        default:
            return "none";
    }
}

const char* alpha_name(AlphaMode m) {
    switch (m) {
        case AlphaMode::Mask:
            return "mask";
        case AlphaMode::Blend:
            return "blend";
        default:
            return "opaque";
    }
}

const char* wrap_name(WrapMode w) {
    switch (w) {
        case WrapMode::ClampToEdge:
            return "clamp";
        case WrapMode::MirroredRepeat:
            return "mirror";
        default:
            return "repeat";
    }
}

const char* support_name(ExtensionSupport s) {
    switch (s) {
        case ExtensionSupport::Supported:
            return "supported";
        case ExtensionSupport::Ignored:
            return "ignored";
        default:
            return "refused";
    }
}

/// " slot=tex3(uv1, scale 0.5, transform ...)" or "" when the slot is empty.
std::string texture_slot(const char* slot, const TextureRef& ref, bool show_scale) {
    if (!ref.valid()) return "";
    std::string s = fmt::format(" {}=tex{}(uv{}", slot, ref.texture, ref.uv_set);
    if (show_scale) s += fmt::format(", scale {}", num(ref.scale));
    if (!ref.transform.identity())
        s += fmt::format(", offset ({}, {}) rotation {} scale ({}, {})", num(ref.transform.offset.x),
                         num(ref.transform.offset.y), num(ref.transform.rotation), num(ref.transform.scale.x),
                         num(ref.transform.scale.y));
    return s + ")";
}

/// The active glTF material extensions of `m` and their factors ("clearcoat=1 roughness=0.1;
/// sheen color=(...) roughness=0.5"), each extension's textures after its factors; "" when none.
std::string material_extensions(const Material& m) {
    std::vector<std::string> parts;
    if (m.clearcoat > 0.f)
        parts.push_back(fmt::format("clearcoat={} roughness={}", num(m.clearcoat), num(m.clearcoat_roughness)) +
                        texture_slot("texture", m.clearcoat_texture, false) +
                        texture_slot("roughness_texture", m.clearcoat_roughness_texture, false) +
                        texture_slot("normal_texture", m.clearcoat_normal_texture, true));
    if (m.sheen_color != Color(0.f))
        parts.push_back(fmt::format("sheen color={} roughness={}", vec3(m.sheen_color), num(m.sheen_roughness)) +
                        texture_slot("color_texture", m.sheen_color_texture, false) +
                        texture_slot("roughness_texture", m.sheen_roughness_texture, false));
    if (m.iridescence > 0.f)
        parts.push_back(fmt::format("iridescence={} ior={} thickness={}..{}nm", num(m.iridescence),
                                    num(m.iridescence_ior), num(m.iridescence_thickness_min),
                                    num(m.iridescence_thickness_max)) +
                        texture_slot("texture", m.iridescence_texture, false) +
                        texture_slot("thickness_texture", m.iridescence_thickness_texture, false));
    if (m.anisotropy_strength > 0.f)
        parts.push_back(fmt::format("anisotropy={} rotation={}", num(m.anisotropy_strength),
                                    num(m.anisotropy_rotation)) +
                        texture_slot("texture", m.anisotropy_texture, false));
    if (m.dispersion > 0.f) parts.push_back(fmt::format("dispersion={}", num(m.dispersion)));
    if (m.diffuse_transmission > 0.f)
        parts.push_back(fmt::format("diffuse_transmission={} color={}", num(m.diffuse_transmission),
                                    vec3(m.diffuse_transmission_color)) +
                        texture_slot("texture", m.diffuse_transmission_texture, false) +
                        texture_slot("color_texture", m.diffuse_transmission_color_texture, false));
    if (m.specular_glossiness)
        parts.push_back(fmt::format("specular-glossiness specular={} glossiness={}", vec3(m.sg_specular),
                                    num(m.glossiness)) +
                        texture_slot("texture", m.specular_glossiness_texture, false));
    std::string out;
    for (const std::string& p : parts) out += (out.empty() ? "" : "; ") + p;
    return out;
}

/// " width=640 aa=adaptive ..." for the settings a scene file set, "" when none.
std::string render_settings(const SceneRenderSettings& s) {
    std::string out;
    auto add = [&](const char* key, const std::string& value) { out += fmt::format(" {}={}", key, value); };
    auto quoted = [](const std::string& v) { return "\"" + v + "\""; };
    if (s.width) add("width", std::to_string(*s.width));
    if (s.height) add("height", std::to_string(*s.height));
    if (s.aa) add("aa", *s.aa);
    if (s.aa_threshold) add("aa_threshold", num(*s.aa_threshold));
    if (s.aa_depth) add("aa_depth", std::to_string(*s.aa_depth));
    if (s.spp) add("spp", std::to_string(*s.spp));
    if (s.max_depth) add("max_depth", std::to_string(*s.max_depth));
    if (s.min_weight) add("min_weight", num(*s.min_weight));
    if (s.background) add("background", vec3(*s.background));
    if (s.ambient) add("ambient", vec3(*s.ambient));
    if (s.exposure) add("exposure", num(*s.exposure));
    if (s.fresnel) add("fresnel", yes_no(*s.fresnel));
    if (s.output) add("output", quoted(*s.output));
    if (s.view) add("view", quoted(*s.view));
    if (s.display) add("display", quoted(*s.display));
    if (s.camera) add("camera", std::to_string(*s.camera));
    return out;
}

/// The environment's light: one line with its size, the extracted lights and their share of the
/// map's power, then (unless every light is listed anyway) the brightest few.
void describe_environment(const Scene& scene, ReportDetail detail, const std::function<void(const std::string&)>& line) {
    const Environment& e = *scene.environment;
    std::vector<size_t> lights;  // indices of the extracted lights, most powerful first
    Color power(0.f);            // their integral of L dw: intensity (lux) times pi
    for (size_t i = 0; i < scene.lights.size(); ++i)
        if (scene.lights[i].from_environment) {
            lights.push_back(i);
            power += scene.lights[i].color * scene.lights[i].intensity * float(std::numbers::pi);
        }
    auto light_power = [&](size_t i) { return luminance(scene.lights[i].color) * double(scene.lights[i].intensity); };
    std::stable_sort(lights.begin(), lights.end(), [&](size_t a, size_t b) { return light_power(a) > light_power(b); });
    // The ambient's integral of L dw from its SH band 0: L00 * 4 pi * Y00 = L00 * 2 sqrt(pi).
    const Color ambient = e.ambient_sh ? (*e.ambient_sh)[0] * float(2.0 * std::sqrt(std::numbers::pi)) : Color(0.f);
    const double total = luminance(power) + std::max(0.0, luminance(ambient));
    const double share = total > 0.0 ? luminance(power) / total : 0.0;
    line(fmt::format("environment: name=\"{}\" size={}x{} rotation={} exposure={} visible={} lights={} "
                     "lights_intensity={} lights_share={}%",
                     e.image->name, e.image->width, e.image->height, num(e.rotation_deg), num(e.exposure_stops),
                     yes_no(e.visible), lights.size(), vec3(power * float(1.0 / std::numbers::pi)),
                     num(std::round(1000.0 * share) / 10.0)));
    if (e.ambient_sh) {
        // The ambient part as irradiance (renderer units: a constant radiance L gives L) along the axes.
        const auto& sh = *e.ambient_sh;
        auto E = [&](const Vec3f& n) { return sh9_irradiance(sh, n); };
        line(fmt::format("environment ambient: +X={} -X={} +Y={} -Y={} +Z={} -Z={}", vec3(E({1, 0, 0})),
                         vec3(E({-1, 0, 0})), vec3(E({0, 1, 0})), vec3(E({0, -1, 0})), vec3(E({0, 0, 1})),
                         vec3(E({0, 0, -1}))));
    }
    if (detail == ReportDetail::Verbose) return;  // every light has its own line
    const double all = luminance(power);
    for (size_t k = 0; k < lights.size() && k < kBrightestEnvironmentLights; ++k) {
        const Light& l = scene.lights[lights[k]];
        line(fmt::format("environment light[{}]: toward={} intensity={} share_of_lights={}%", lights[k],
                         vec3(-l.direction), num(l.intensity * luminance(l.color)),
                         num(all > 0 ? std::round(1000.0 * light_power(lights[k]) * std::numbers::pi / all) / 10.0 : 0.0)));
    }
    if (lights.size() > kBrightestEnvironmentLights)
        line(fmt::format("environment lights: {} more (whitted info --verbose lists every light)",
                         lights.size() - kBrightestEnvironmentLights));
}

/// What the file animates: its animations (the posed ones at scene.time), skins and morph targets.
void describe_motion(const Scene& scene, const std::function<void(const std::string&)>& line) {
    if (!scene.animations.empty()) line(fmt::format("pose: time={}s", num(scene.time)));
    for (size_t i = 0; i < scene.animations.size(); ++i) {
        const AnimationInfo& a = scene.animations[i];
        line(fmt::format("animation[{}]: name=\"{}\" duration={}s channels={} interpolation={} posed={}", i, a.name,
                         num(a.duration), a.channels, a.interpolations, yes_no(a.posed)));
    }
    for (size_t i = 0; i < scene.skins.size(); ++i) {
        const SkinInfo& k = scene.skins[i];
        line(fmt::format("skin[{}]: name=\"{}\" joints={} instances={}", i, k.name, k.joints, k.meshes));
    }
    for (size_t i = 0; i < scene.morphs.size(); ++i) {
        const MorphInfo& m = scene.morphs[i];
        std::string weights;
        for (const float w : m.default_weights) {
            if (!weights.empty()) weights += ',';
            weights += num(w);
        }
        line(fmt::format("morph[{}]: mesh=\"{}\" targets={} default_weights={}", i, m.mesh, m.targets,
                         weights.empty() ? "0" : weights));
    }
    // KHR_materials_variants: the file's material sets (--variant NAME).
    for (size_t i = 0; i < scene.variants.size(); ++i)
        line(fmt::format("variant[{}]: name=\"{}\" applied={}", i, scene.variants[i],
                         yes_no(scene.variants[i] == scene.variant)));
}

}  // namespace

std::string describe_scene(const Scene& scene, ReportDetail detail) {
    std::string out;
    auto line = [&](const std::string& s) {
        out += s;
        out += '\n';
    };
    line(fmt::format("file: {}", scene.source));
    line(
        fmt::format("counts: meshes={} triangles={} instanced_triangles={} instances={} spheres={} quadrics={} "
                    "materials={} textures={} lights={} cameras={} planes={} warnings={}",
                    scene.meshes.size(), scene.mesh_triangle_count(), scene.instanced_triangle_count(),
                    scene.instances.size(), scene.spheres.size(), scene.quadrics.size(), scene.materials.size(), scene.textures.size(),
                    scene.lights.size(), scene.cameras.size(), scene.planes.size(), scene.warnings.size()));
    const Bounds3d b = scene.world_bounds();
    if (b.empty())
        line("bounds: empty");
    else
        line(fmt::format("bounds: min={} max={} center={} diagonal={}", vec3(b.lo), vec3(b.hi), vec3(b.center()),
                         num(length(b.diagonal()))));
    if (const std::string rs = render_settings(scene.settings); !rs.empty()) line("settings:" + rs);

    // Analytic primitives (scene files).
    for (size_t i = 0; i < scene.spheres.size(); ++i) {
        const Sphere& sp = scene.spheres[i];
        line(fmt::format("sphere[{}]: name=\"{}\" center={} radius={} material={}", i, sp.name, vec3(sp.center),
                         num(sp.radius), sp.material));
    }
    for (size_t i = 0; i < scene.quadrics.size(); ++i) {
        const Quadric& q = scene.quadrics[i];
        static constexpr const char* kKinds[] = {"cylinder", "cone", "disc"};
        const Bounds3d qb = quadric_bounds(q);
        const std::string shape =
            q.kind == QuadricKind::Disc
                ? fmt::format("radius={} inner_radius={}", num(q.radius0), num(q.inner_radius))
                : fmt::format("radius0={} radius1={} height={} caps={}", num(q.radius0), num(q.radius1), num(q.height),
                              q.caps ? "yes" : "no");
        line(fmt::format("{}[{}]: name=\"{}\" {} bounds=({}, {}) material={}", kKinds[int(q.kind)], i, q.name, shape,
                         vec3(qb.lo), vec3(qb.hi), q.material));
    }
    for (size_t i = 0; i < scene.planes.size(); ++i) {
        const Plane& pl = scene.planes[i];
        line(fmt::format("plane[{}]: name=\"{}\" point={} normal={} u_axis={} material={} infinite=yes", i, pl.name,
                         vec3(pl.point), vec3(pl.normal), vec3(pl.u_axis), pl.material));
    }

    for (size_t i = 0; i < scene.lights.size(); ++i) {
        const Light& l = scene.lights[i];
        if (l.from_environment && detail == ReportDetail::Summary) continue;  // summarised with the environment
        std::string s =
            fmt::format("light[{}]: name=\"{}\" type={} color={} intensity={} range={}", i, l.name, light_type(l.type),
                        vec3(l.color), num(l.intensity), l.range > 0 ? num(l.range) : std::string("inf"));
        if (l.type == LightType::Spot)
            s += fmt::format(" inner_cone={} outer_cone={}", num(l.inner_cone), num(l.outer_cone));
        if (l.type != LightType::Directional) s += fmt::format(" position={}", vec3(l.position));
        if (l.type != LightType::Point) s += fmt::format(" direction={}", vec3(l.direction));
        s += fmt::format(" attenuation={} default={}", attenuation_name(l.attenuation), yes_no(l.is_default));
        if (l.from_environment) s += " environment=yes";
        line(s);
    }
    if (scene.environment && scene.environment->image) describe_environment(scene, detail, line);
    describe_motion(scene, line);

    for (size_t i = 0; i < scene.cameras.size(); ++i) {
        const Camera& c = scene.cameras[i];
        const Vec3d pos = c.world_from_camera.apply_point(Vec3d(0.0));
        const Vec3d fwd = normalize(c.world_from_camera.apply_vector({0, 0, -1}));
        std::string s = fmt::format("camera[{}]: name=\"{}\" ", i, c.name);
        if (c.type == CameraType::Perspective)
            s += fmt::format("type=perspective yfov={} yfov_deg={}", num(c.yfov), num(c.yfov * 180 / std::numbers::pi));
        else
            s += fmt::format("type=orthographic xmag={} ymag={}", num(c.xmag), num(c.ymag));
        s += fmt::format(" aspect={} znear={} zfar={} position={} forward={} default={}",
                         c.aspect > 0 ? num(c.aspect) : std::string("unset"), num(c.znear),
                         c.zfar > 0 ? num(c.zfar) : std::string("inf"), vec3(pos), vec3(fwd), yes_no(c.is_default));
        line(s);
    }

    // Materials as the file gives them, then the Whitted coefficients of their factors alone.
    const MappingOptions mapping{};
    for (size_t i = 0; i < scene.materials.size(); ++i) {
        const Material& m = scene.materials[i];
        if (m.model == MaterialModel::GltfPbr) {
            line(fmt::format(
                "material[{}]: name=\"{}\" model=gltf base_color={} metallic={} roughness={} "
                "emissive={} emissive_strength={} transmission={} ior={} volume={} thickness={} "
                "attenuation_color={} attenuation_distance={} specular={} specular_color={} unlit={} "
                "alpha={} alpha_cutoff={} double_sided={}",
                i, m.name, vec4(m.base_color), num(m.metallic), num(m.roughness), vec3(m.emissive),
                num(m.emissive_strength), num(m.transmission), num(m.ior), yes_no(m.has_volume), num(m.thickness),
                vec3(m.attenuation_color), num(m.attenuation_distance), num(m.specular), vec3(m.specular_color),
                yes_no(m.unlit), alpha_name(m.alpha_mode), num(m.alpha_cutoff), yes_no(m.double_sided)));
        } else {
            line(fmt::format("material[{}]: name=\"{}\" model=classic double_sided={}", i, m.name,
                             yes_no(m.double_sided)));
        }
        const WhittedCoeffs c = map_material_constant(m, mapping);
        line(
            fmt::format("material[{}] whitted: kd={} ka={} ks={} n={} kr={} kt={} ior={} thin={} emission={} "
                        "absorption={} kg={} roughness={}",
                        i, vec3(c.kd), vec3(c.ka), vec3(c.ks), num(c.n), vec3(c.kr), vec3(c.kt), num(c.ior),
                        yes_no(c.thin), vec3(c.emission), vec3(c.absorption), vec3(c.kg), num(c.roughness)));
        const std::string tex = texture_slot("base_color", m.base_color_texture, false) +
                                texture_slot("metallic_roughness", m.metallic_roughness_texture, false) +
                                texture_slot("normal", m.normal_texture, true) +
                                texture_slot("occlusion", m.occlusion_texture, true) +
                                texture_slot("emissive", m.emissive_texture, false) +
                                texture_slot("transmission", m.transmission_texture, false) +
                                texture_slot("specular", m.specular_texture, false) +
                                texture_slot("specular_color", m.specular_color_texture, false) +
                                texture_slot("classic_color", m.classic_color_texture, false);
        line(fmt::format("material[{}] textures:{}", i, tex.empty() ? " none" : tex));
        if (const std::string ext = material_extensions(m); !ext.empty())
            line(fmt::format("material[{}] extensions: {}", i, ext));
    }

    for (size_t i = 0; i < scene.textures.size(); ++i) {
        const Texture& t = scene.textures[i];
        if (t.kind == TextureKind::Checker) {
            line(fmt::format("texture[{}]: name=\"{}\" kind=checker color_a={} color_b={} size={} space={}", i, t.name,
                             vec3(t.checker.color_a), vec3(t.checker.color_b), num(t.checker.size),
                             t.checker.world_space ? "world" : "uv"));
            continue;
        }
        const std::string size =
            t.levels.empty() ? std::string("not-loaded") : fmt::format("{}x{}", t.levels[0].width, t.levels[0].height);
        line(fmt::format("texture[{}]: name=\"{}\" size={} levels={} srgb={} wrap={}/{} filter={}/{} mips={} image={}",
                         i, t.name, size, t.levels.size(), yes_no(t.srgb), wrap_name(t.wrap_s), wrap_name(t.wrap_t),
                         t.mag_filter == FilterMode::Nearest ? "nearest" : "linear",
                         t.min_filter == FilterMode::Nearest ? "nearest" : "linear", yes_no(t.use_mips), t.image));
    }

    for (const ExtensionUse& e : scene.extensions)
        line(fmt::format("extension: {} {} required={} note=\"{}\"", e.name, support_name(e.support),
                         yes_no(e.required), e.note));
    for (const CompressedPrimitive& c : scene.compressed)
        line(fmt::format("compressed: primitive={} codec={} compressed_bytes={} decoded_bytes={} ratio={}", c.pointer,
                         c.codec, c.compressed_bytes, c.decoded_bytes,
                         c.compressed_bytes ? num(double(c.decoded_bytes) / double(c.compressed_bytes)) : "inf"));
    for (const std::string& w : scene.warnings) line("warning: " + w);
    out += describe_analysis(scene, analyze_scene(scene), detail);
    return out;
}

std::string describe_analysis(const Scene& scene, const SceneAnalysis& a, ReportDetail detail) {
    std::string out;
    auto line = [&](const std::string& s) {
        out += s;
        out += '\n';
    };
    const SceneFeatures& f = a.features;
    line(fmt::format("analysis: opaque={} recursive={} mirror={} transmission={} alpha_blend={} alpha_mask={} "
                     "textured={} vertex_colors={} varying={} emissive={} unlit={} volume={} single_sided={} "
                     "highlight={} diffuse={}",
                     yes_no(f.opaque()), yes_no(f.recursive()), yes_no(f.mirror), yes_no(f.transmission),
                     yes_no(f.alpha_blend), yes_no(f.alpha_mask), yes_no(f.textured), yes_no(f.vertex_colors),
                     yes_no(f.varying), yes_no(f.emissive), yes_no(f.unlit), yes_no(f.volume), yes_no(f.single_sided),
                     yes_no(f.highlight), yes_no(f.diffuse)));
    const double per_tri = a.triangles ? double(a.scene_bytes) / double(a.triangles) : 0.0;
    const double per_sphere = a.spheres ? double(a.sphere_bytes) / double(a.spheres) : 0.0;
    line(fmt::format("analysis memory: triangles={} scene_bytes={} bytes_per_triangle={} texture_bytes={} spheres={} "
                     "sphere_bytes={} bytes_per_sphere={}",
                     a.triangles, a.scene_bytes, num(per_tri), a.texture_bytes, a.spheres, a.sphere_bytes, num(per_sphere)));
    for (size_t i = 0; i < a.materials.size(); ++i) {
        const MaterialFeatures& m = a.materials[i];
        line(fmt::format("analysis material[{}]: used={} diffuse={} highlight={} mirror={} transmission={} emissive={} "
                         "unlit={} textured={} vertex_colors={} alpha_mask={} alpha_blend={} volume={} "
                         "single_sided={} varying={}",
                         i, yes_no(m.used), yes_no(m.diffuse), yes_no(m.highlight), yes_no(m.mirror),
                         yes_no(m.transmission), yes_no(m.emissive), yes_no(m.unlit), yes_no(m.textured),
                         yes_no(m.vertex_colors), yes_no(m.alpha_mask), yes_no(m.alpha_blend), yes_no(m.volume),
                         yes_no(m.single_sided), yes_no(m.varying)));
    }
    for (size_t i = 0; i < a.lights.size() && i < scene.lights.size(); ++i) {
        if (scene.lights[i].from_environment && detail == ReportDetail::Summary) continue;
        const LightReach& r = a.lights[i];
        line(fmt::format("analysis light[{}]: reach={}/{} culled_range={} culled_cone={} facing=per-point", i,
                         r.objects_reached, a.object_count, r.culled_range, r.culled_cone));
    }
    return out;
}

}  // namespace whitted
