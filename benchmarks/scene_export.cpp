// Classic scenes written as whitted scene files and as POV-Ray scenes (see scene_export.h).
#include "benchmarks/scene_export.h"

#include <array>
#include <charconv>
#include <cmath>
#include <functional>
#include <optional>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/error.h"

namespace whitted::app {

namespace {

using Json = nlohmann::ordered_json;

std::string what(const Scene& scene) { return scene.source.empty() ? std::string("scene") : scene.source; }

[[noreturn]] void unsupported(const Scene& scene, const std::string& item) {
    throw Error(fmt::format("{}: cannot export {} (the exporters write classic scenes: spheres, cylinders, cones, discs, "
                            "meshes, infinite planes, classic materials with a world-space checker, point and "
                            "directional lights, a perspective camera)",
                            what(scene), item));
}

/// A float as the double of its shortest decimal form (std::to_chars), so that the file says 0.55
/// rather than 0.550000011920929 and reads back as the same float (checked; else the float itself).
double short_float(float f) {
    std::array<char, 32> buf;
    const auto [end, ec] = std::to_chars(buf.data(), buf.data() + buf.size(), f);
    if (ec != std::errc()) return double(f);
    double d = 0.0;
    const auto [at, ec2] = std::from_chars(buf.data(), end, d);
    return ec2 == std::errc() && at == end && float(d) == f ? d : double(f);
}

Json vec(const Vec3d& v) { return Json::array({v.x, v.y, v.z}); }
Json vecf(const Vec3f& v) { return Json::array({short_float(v.x), short_float(v.y), short_float(v.z)}); }
Json col(const Color& c) { return vecf(c); }

/// The 16 numbers of a scene file's `matrix` (column-major).
Json column_major(const Mat4d& m) {
    Json a = Json::array();
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) a.push_back(m(r, c));
    return a;
}

const Camera& the_camera(const Scene& scene) {
    if (scene.cameras.empty()) unsupported(scene, "a scene without a camera");
    const Camera& c = scene.cameras[size_t(scene.settings.camera.value_or(0))];
    if (c.type != CameraType::Perspective) unsupported(scene, "an orthographic camera");
    return c;
}

/// The classic material `m`, checked: its color texture (null for none) is a world-space checker.
const Checker* classic_material(const Scene& scene, const Material& m) {
    if (m.model != MaterialModel::Classic) unsupported(scene, fmt::format("material '{}' (not a classic material)", m.name));
    if (!is_black(m.classic.emission) || !is_black(m.classic.absorption))
        unsupported(scene, fmt::format("material '{}' (emission or absorption)", m.name));
    if (!m.classic_color_texture.valid()) return nullptr;
    const Texture& t = scene.textures[size_t(m.classic_color_texture.texture)];
    if (t.kind != TextureKind::Checker || !t.checker.world_space)
        unsupported(scene, fmt::format("material '{}' (its texture is not a world-space checker)", m.name));
    return &t.checker;
}

void check_light(const Scene& scene, const Light& l) {
    if (l.type == LightType::Spot) unsupported(scene, fmt::format("light '{}' (a spot light)", l.name));
    if (l.range > 0.f) unsupported(scene, fmt::format("light '{}' (a range window)", l.name));
    if (l.from_environment) unsupported(scene, "an environment's lights");
}

float mean(const Color& c) { return (c.x + c.y + c.z) / 3.f; }

}  // namespace

ExportSettings export_settings(const Scene& scene, int width, int height) {
    ExportSettings s;
    s.width = width;
    s.height = height;
    const SceneRenderSettings& r = scene.settings;
    s.max_depth = r.max_depth.value_or(s.max_depth);
    s.min_weight = r.min_weight.value_or(s.min_weight);
    s.ambient = r.ambient.value_or(s.ambient);
    s.background = r.background.value_or(s.background);
    return s;
}

// ---- whitted scene file ---------------------------------------------------------------------------

std::string to_scene_file(const Scene& scene, const ExportSettings& s) {
    if (scene.environment) unsupported(scene, "an environment");
    Json j;
    j["version"] = 1;
    j["render"] = {{"width", s.width},           {"height", s.height},         {"max_depth", s.max_depth},
                   {"min_weight", s.min_weight}, {"background", col(s.background)}};
    j["ambient"] = col(s.ambient);
    const Camera& cam = the_camera(scene);
    const Mat4d& m = cam.world_from_camera;
    const Vec3d eye{m(0, 3), m(1, 3), m(2, 3)}, z{m(0, 2), m(1, 2), m(2, 2)}, y{m(0, 1), m(1, 1), m(2, 1)};
    j["camera"] = {{"position", vec(eye)}, {"look_at", vec(eye - z)}, {"up", vec(y)}, {"fov", cam.yfov * 180.0 / kPiD}};

    Json textures = Json::object(), materials = Json::object();
    for (size_t i = 0; i < scene.materials.size(); ++i) {
        const Material& mat = scene.materials[i];
        const Checker* checker = classic_material(scene, mat);
        const WhittedCoeffs& c = mat.classic;
        Json jm;
        if (checker) {
            if (!(c.kd == Color(1.f))) unsupported(scene, fmt::format("material '{}' (kd scales its texture)", mat.name));
            const std::string t = fmt::format("t{}", i);
            textures[t] = {{"type", "checker"},
                           {"colors", Json::array({col(checker->color_a), col(checker->color_b)})},
                           {"size", checker->size},
                           {"space", "world"}};
            jm["kd"] = t;
        } else {
            jm["kd"] = col(c.kd);
        }
        jm["ka"] = col(c.ka);  // the texture, if any, multiplies it
        jm["highlight"] = col(c.ks);
        jm["n"] = c.n;
        jm["kr"] = col(c.kr);
        jm["kt"] = col(c.kt);
        jm["ior"] = c.ior;
        jm["thin"] = c.thin;
        materials[fmt::format("m{}", i)] = jm;
    }
    if (!textures.empty()) j["textures"] = textures;
    j["materials"] = materials;

    auto material = [](uint32_t k) { return fmt::format("m{}", k); };
    Json objects = Json::array();
    for (const Sphere& sp : scene.spheres)
        objects.push_back({{"type", "sphere"}, {"center", vec(sp.center)}, {"radius", sp.radius}, {"material", material(sp.material)}});
    for (const Quadric& q : scene.quadrics) {
        Json o;
        switch (q.kind) {
            case QuadricKind::Cylinder:
                o = {{"type", "cylinder"}, {"base", vec({0, 0, 0})}, {"apex", vec({0, 0, q.height})}, {"radius", q.radius0},
                     {"open", !q.caps}};
                break;
            case QuadricKind::Cone:
                o = {{"type", "cone"},          {"base", vec({0, 0, 0})},     {"apex", vec({0, 0, q.height})},
                     {"base_radius", q.radius0}, {"apex_radius", q.radius1}, {"open", !q.caps}};
                break;
            case QuadricKind::Disc:
                o = {{"type", "disc"}, {"center", vec({0, 0, 0})}, {"normal", vec({0, 0, 1})}, {"radius", q.radius0},
                     {"inner_radius", q.inner_radius}};
                break;
        }
        o["material"] = material(q.material);
        o["transform"] = {{"matrix", column_major(q.world_from_object)}};
        objects.push_back(o);
    }
    for (const Instance& in : scene.instances) {
        const Mesh& mesh = scene.meshes[in.mesh];
        Json pos = Json::array(), nrm = Json::array();
        for (const Vec3f& p : mesh.positions) pos.push_back(vecf(p));
        for (const Vec3f& n : mesh.normals) nrm.push_back(vecf(n));
        Json o = {{"type", "mesh"}, {"positions", pos}, {"indices", mesh.indices}};
        if (!nrm.empty()) o["normals"] = nrm;
        o["material"] = material(mesh.material);
        o["transform"] = {{"matrix", column_major(in.world_from_object)}};
        objects.push_back(o);
    }
    for (const Plane& p : scene.planes)
        objects.push_back({{"type", "plane"}, {"point", vec(p.point)}, {"normal", vec(p.normal)}, {"u_axis", vec(p.u_axis)},
                           {"material", material(p.material)}});
    j["objects"] = objects;

    Json lights = Json::array();
    for (const Light& l : scene.lights) {
        if (l.is_default) continue;
        check_light(scene, l);
        Json o = {{"type", l.type == LightType::Point ? "point" : "directional"}, {"color", col(l.color)}, {"intensity", l.intensity}};
        if (l.type == LightType::Point) {
            o["position"] = vec(l.position);
            if (l.attenuation == Attenuation::Classic)
                o["attenuation"] = Json::array({l.classic_c.x, l.classic_c.y, l.classic_c.z});
            else
                o["attenuation"] = l.attenuation == Attenuation::None ? "none" : "inverse_square";
        } else {
            o["direction"] = vec(l.direction);
        }
        lights.push_back(o);
    }
    j["lights"] = lights;
    // Compact: a mesh's numbers one per line made the exported files 3x longer and slower to read.
    return j.dump() + "\n";
}

// ---- POV-Ray 3.7 ----------------------------------------------------------------------------------

namespace {

std::string pv(const Vec3d& v) { return fmt::format("<{}, {}, {}>", v.x, v.y, v.z); }
std::string pc(const Color& c) { return fmt::format("rgb <{}, {}, {}>", c.x, c.y, c.z); }

/// POV-Ray's `matrix` of an affine transform: points are row vectors (p' = p M), so row r of its
/// 4x3 is column r of ours.
std::string pov_matrix(const Mat4d& m) {
    std::string s = "matrix <";
    for (int r = 0; r < 4; ++r)
        s += fmt::format("{}{}, {}, {}", r ? ", " : "", m(0, r), m(1, r), m(2, r));
    return s + ">";
}

/// A surface that bends what it transmits (a thin one passes it straight on).
bool refracts(const WhittedCoeffs& c) { return !is_black(c.kt) && !c.thin; }

}  // namespace

std::string to_povray(const Scene& scene, const ExportSettings& s) {
    if (scene.environment) unsupported(scene, "an environment");
    std::string out = fmt::format("// {} for POV-Ray 3.7, written by whitted (benchmarks/scene_export.cpp)\n#version 3.7;\n",
                                  what(scene));
    out += fmt::format("global_settings {{ assumed_gamma 1.0 max_trace_level {} adc_bailout {} ambient_light {} }}\n",
                       s.max_depth + 1, s.min_weight, pc(s.ambient));
    out += fmt::format("background {{ {} }}\n", pc(s.background));
    // The camera: image right along the camera's x, up along its y, looking down its -z; up's
    // length 1 against the direction's sets the vertical field of view.
    const Camera& cam = the_camera(scene);
    const Mat4d& m = cam.world_from_camera;
    const Vec3d eye{m(0, 3), m(1, 3), m(2, 3)}, x{m(0, 0), m(1, 0), m(2, 0)}, y{m(0, 1), m(1, 1), m(2, 1)},
        z{m(0, 2), m(1, 2), m(2, 2)};
    const double aspect = double(s.width) / double(s.height), focal = 0.5 / std::tan(0.5 * cam.yfov);
    out += fmt::format("camera {{ perspective location {} direction {} right {} up {} }}\n", pv(eye), pv(z * -focal),
                       pv(x * aspect), pv(y));

    for (const Light& l : scene.lights) {
        if (l.is_default) continue;
        check_light(scene, l);
        const Color c = l.color * l.intensity;
        if (l.type == LightType::Directional) {
            // Parallel rays along `direction`, from far behind the scene.
            const Bounds3d b = scene.world_bounds();
            const Vec3d centre = b.empty() ? Vec3d{0, 0, 0} : b.center();
            const double far = b.empty() ? 1e4 : 1e3 * (length(b.diagonal()) + 1.0);
            out += fmt::format("light_source {{ {} color {} parallel point_at {} }}\n", pv(centre - l.direction * far), pc(c),
                               pv(centre));
            continue;
        }
        switch (l.attenuation) {
            case Attenuation::None: out += fmt::format("light_source {{ {} color {} }}\n", pv(l.position), pc(c)); break;
            case Attenuation::InverseSquare: {
                // POV-Ray's fade is 2 / (1 + (d / D)^2) = 2 D^2 / (D^2 + d^2): with colour I / (2 D^2)
                // it is I / d^2 wherever d >> D.
                constexpr double D = 1e-3;
                out += fmt::format("light_source {{ {} color {} fade_distance {} fade_power 2 }}\n", pv(l.position),
                                   pc(c * float(1.0 / (2.0 * D * D))), D);
                break;
            }
            case Attenuation::Classic:
                if (!(l.classic_c == Vec3f(1.f, 0.f, 0.f)))
                    unsupported(scene, fmt::format("light '{}' (classic attenuation other than [1, 0, 0])", l.name));
                out += fmt::format("light_source {{ {} color {} }}\n", pv(l.position), pc(c));
                break;
        }
    }

    // Absolute indices of refraction: a scene file's ior is relative to the medium outside the
    // object; POV-Ray takes each object's own and divides by the enclosing one's. Spheres inside
    // refracting spheres (the classic hollow glass shell) multiply their container's.
    std::vector<double> sphere_ior(scene.spheres.size(), 0.0);
    std::function<double(size_t)> absolute = [&](size_t i) -> double {
        if (sphere_ior[i] > 0.0) return sphere_ior[i];
        const Sphere& a = scene.spheres[i];
        const WhittedCoeffs& c = scene.materials[a.material].classic;
        double container = 1.0;
        size_t best = scene.spheres.size();
        for (size_t k = 0; k < scene.spheres.size(); ++k) {
            const Sphere& b = scene.spheres[k];
            if (k == i || b.radius <= a.radius || !refracts(scene.materials[b.material].classic)) continue;
            if (length(a.center - b.center) + a.radius <= b.radius &&
                (best == scene.spheres.size() || b.radius < scene.spheres[best].radius))
                best = k;
        }
        if (best < scene.spheres.size()) container = absolute(best);
        return sphere_ior[i] = refracts(c) ? double(c.ior) * container : container;
    };

    for (size_t i = 0; i < scene.materials.size(); ++i) {
        const Material& mat = scene.materials[i];
        const Checker* checker = classic_material(scene, mat);
        const WhittedCoeffs& c = mat.classic;
        // pigment x diffuse = kd; pigment x ambient (x ambient_light) = ka.
        std::string pigment;
        float diffuse = 0.f;
        Color ambient = c.ka, base(1.f);
        const float transmit = mean(c.kt);
        if (checker) {
            pigment = fmt::format("checker {}, {} scale {}", pc(checker->color_a), pc(checker->color_b), checker->size);
            if (transmit > 0.f) unsupported(scene, fmt::format("material '{}' (a transmissive checker)", mat.name));
            diffuse = mean(c.kd);
        } else {
            if (!is_black(c.kd)) {
                base = c.kd;
                diffuse = 1.f;
                ambient = Color(c.kd.x > 0.f ? c.ka.x / c.kd.x : 0.f, c.kd.y > 0.f ? c.ka.y / c.kd.y : 0.f,
                                c.kd.z > 0.f ? c.ka.z / c.kd.z : 0.f);
            }
            pigment = fmt::format("rgbt <{}, {}, {}, {}>", base.x, base.y, base.z, transmit);
        }
        std::string finish = fmt::format("ambient {} diffuse {}", pc(ambient), diffuse);
        if (!is_black(c.ks)) finish += fmt::format(" specular {} roughness {}", mean(c.ks), std::clamp(1.0 / c.n, 5e-4, 1.0));
        if (!is_black(c.kr)) finish += fmt::format(" reflection {{ {} }}", pc(c.kr));
        out += fmt::format("#declare T{} = texture {{ pigment {{ {} }} finish {{ {} }} }}\n", i, pigment, finish);
    }
    // The material of an object: its texture (moved by `shift`), and an interior where it refracts.
    auto material = [&](uint32_t k, double ior, const std::string& shift = {}) {
        const std::string t = fmt::format("texture {{ T{}{} }}", k, shift);
        if (!refracts(scene.materials[k].classic)) return t;
        return fmt::format("{} interior {{ ior {} }}", t, ior);
    };
    // whitted evaluates a world-space checker a tiny step inside the surface (so an axis-aligned
    // face does not sit on the cells' boundary); POV-Ray at the point itself. A flat mesh with
    // such a checker (and a plane) gets its pigment moved by the same step along its normal: the
    // same squares.
    auto shift_along = [&](uint32_t material, const Vec3d& normal) -> std::string {
        const Checker* checker = classic_material(scene, scene.materials[material]);
        if (!checker) return {};
        return " translate " + pv(normal * (1e-4 * double(checker->size)));
    };
    auto checker_shift = [&](const Instance& in) -> std::string {
        const Mesh& mesh = scene.meshes[in.mesh];
        if (!classic_material(scene, scene.materials[mesh.material]) || mesh.triangle_count() == 0) return {};
        std::optional<Vec3d> normal;
        const uint32_t inst = uint32_t(&in - scene.instances.data());
        for (uint32_t t = 0; t < mesh.triangle_count(); ++t) {
            Vec3d v[3];
            scene.world_triangle(inst, t, v);
            const Vec3d n = normalize(cross(v[1] - v[0], v[2] - v[0]));
            if (!normal) normal = n;
            else if (length(n - *normal) > 1e-9) return {};
        }
        return shift_along(mesh.material, *normal);
    };
    for (size_t i = 0; i < scene.spheres.size(); ++i) {
        const Sphere& sp = scene.spheres[i];
        out += fmt::format("sphere {{ {}, {} {} }}\n", pv(sp.center), sp.radius, material(sp.material, absolute(i)));
    }
    for (const Quadric& q : scene.quadrics) {
        const std::string open = q.caps ? "" : " open";
        // The transform before the material: a world-space pigment is not moved with the object.
        const std::string tail =
            fmt::format("{} {}", pov_matrix(q.world_from_object), material(q.material, scene.materials[q.material].classic.ior));
        switch (q.kind) {
            case QuadricKind::Cylinder:
                out += fmt::format("cylinder {{ <0, 0, 0>, <0, 0, {}>, {}{} {} }}\n", q.height, q.radius0, open, tail);
                break;
            case QuadricKind::Cone:
                out += fmt::format("cone {{ <0, 0, 0>, {}, <0, 0, {}>, {}{} {} }}\n", q.radius0, q.height, q.radius1, open, tail);
                break;
            case QuadricKind::Disc:
                out += fmt::format("disc {{ <0, 0, 0>, <0, 0, 1>, {}, {} {} }}\n", q.radius0, q.inner_radius, tail);
                break;
        }
    }
    for (const Instance& in : scene.instances) {
        const Mesh& mesh = scene.meshes[in.mesh];
        out += fmt::format("mesh2 {{\n vertex_vectors {{ {}", mesh.positions.size());
        for (const Vec3f& p : mesh.positions) out += fmt::format(", <{}, {}, {}>", p.x, p.y, p.z);
        out += " }\n";
        if (!mesh.normals.empty()) {
            out += fmt::format(" normal_vectors {{ {}", mesh.normals.size());
            for (const Vec3f& n : mesh.normals) out += fmt::format(", <{}, {}, {}>", n.x, n.y, n.z);
            out += " }\n";
        }
        out += fmt::format(" face_indices {{ {}", mesh.triangle_count());
        for (size_t t = 0; t < mesh.triangle_count(); ++t)
            out += fmt::format(", <{}, {}, {}>", mesh.indices[3 * t], mesh.indices[3 * t + 1], mesh.indices[3 * t + 2]);
        out += fmt::format(" }}\n {} {}\n}}\n", pov_matrix(in.world_from_object),
                           material(mesh.material, scene.materials[mesh.material].classic.ior, checker_shift(in)));
    }
    for (const Plane& p : scene.planes)
        out += fmt::format("plane {{ {}, {} {} }}\n", pv(p.normal), dot(p.normal, p.point),
                           material(p.material, scene.materials[p.material].classic.ior,
                                    shift_along(p.material, p.normal)));
    return out;
}

}  // namespace whitted::app
