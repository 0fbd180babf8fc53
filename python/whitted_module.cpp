// The Python module `whitted` (docs/python.md): scenes, renders into NumPy arrays that own the
// film's memory, the display transform `render` writes PNGs with, and ray queries through any
// accelerator. A thin layer: every decision is the library's (include/whitted/whitted.h).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "accel/factory/create_accelerator.h"
#include "core/data_files.h"
#include "core/log.h"
#include "core/parallel.h"
#include "whitted/whitted.h"

namespace py = pybind11;

namespace whitted {
namespace {

/// A loaded scene and the ray-query structures built for it so far (one per accelerator spec).
struct PyScene {
    struct Queries {
        std::unique_ptr<SceneView> view;
        std::unique_ptr<Accelerator> accel;
    };
    std::string path;
    Scene scene;
    std::map<std::string, Queries> queries;

    const Queries& queries_for(const std::string& spec) {
        auto it = queries.find(spec);
        if (it != queries.end()) return it->second;
        Queries q;
        q.view = std::make_unique<SceneView>(scene, MappingOptions{});
        AccelConfig config;
        config.robust = true;
        q.accel = create_accelerator(spec, scene, *q.view, config);
        return queries.emplace(spec, std::move(q)).first->second;
    }
};

/// A rendered film, shared by the arrays that view its buffers.
struct PyImage {
    std::shared_ptr<Film> film;
    RenderStats stats;
};

/// A view of `data` (owned by `film`) as an array of `shape`, kept alive by the film.
template <typename T>
py::array view_of(const std::shared_ptr<Film>& film, const T* data, std::vector<py::ssize_t> shape) {
    py::capsule owner(new std::shared_ptr<Film>(film), [](void* p) { delete static_cast<std::shared_ptr<Film>*>(p); });
    return py::array_t<T>(shape, data, owner);
}

py::array beauty_of(const PyImage& img) {
    const Film& f = *img.film;
    return view_of(img.film, reinterpret_cast<const float*>(f.beauty.data()),
                   {f.window.height(), f.window.width(), 3});
}

py::dict aovs_of(const PyImage& img) {
    const Film& f = *img.film;
    const py::ssize_t h = f.window.height(), w = f.window.width();
    py::dict d;
    if (f.aovs.depth) d["depth"] = view_of(img.film, f.depth.data(), {h, w});
    if (f.aovs.normal) d["normal"] = view_of(img.film, reinterpret_cast<const float*>(f.normal.data()), {h, w, 3});
    if (f.aovs.albedo) d["albedo"] = view_of(img.film, reinterpret_cast<const float*>(f.albedo.data()), {h, w, 3});
    if (f.aovs.prim_id) d["prim_id"] = view_of(img.film, f.prim_id.data(), {h, w});
    if (f.aovs.inst_id) d["inst_id"] = view_of(img.film, f.inst_id.data(), {h, w});
    if (f.aovs.aa_samples) d["aa_samples"] = view_of(img.film, f.aa_samples.data(), {h, w});
    return d;
}

using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;

std::string shape_text(const py::array& a) {
    std::string s = "(";
    for (py::ssize_t i = 0; i < a.ndim(); ++i) s += fmt::format("{}{}", i ? ", " : "", a.shape(i));
    return s + (a.ndim() == 1 ? ",)" : ")");
}

/// `obj` as a contiguous float32 array of shape (n, 3) (float64 and other real types converted);
/// a ValueError naming `name` and the expected shape otherwise. n < 0: any n.
FloatArray vectors_arg(const py::handle& obj, const char* name, py::ssize_t n) {
    const py::array raw = py::array::ensure(obj);
    if (!raw || raw.dtype().kind() == 'O' || raw.dtype().kind() == 'U' || raw.dtype().kind() == 'S')
        throw py::value_error(fmt::format("{}: expected a float array of shape (N, 3)", name));
    if (raw.ndim() != 2 || raw.shape(1) != 3 || (n >= 0 && raw.shape(0) != n))
        throw py::value_error(fmt::format("{}: expected shape ({}, 3), got {}", name, n >= 0 ? std::to_string(n) : "N",
                                          shape_text(raw)));
    return FloatArray::ensure(raw);
}

/// tmax (or tmin): a number for every ray, or one per ray.
std::vector<float> per_ray_arg(const py::handle& obj, const char* name, py::ssize_t n, float fallback) {
    std::vector<float> out(size_t(n), fallback);
    if (obj.is_none()) return out;
    if (py::isinstance<py::float_>(obj) || py::isinstance<py::int_>(obj)) {
        std::fill(out.begin(), out.end(), obj.cast<float>());
        return out;
    }
    const py::array raw = py::array::ensure(obj);
    if (!raw || raw.ndim() != 1 || raw.shape(0) != n)
        throw py::value_error(fmt::format("{}: expected a number or shape ({},), got {}", name, n,
                                          raw ? shape_text(raw) : std::string("a non-array")));
    const FloatArray a = FloatArray::ensure(raw);
    std::copy(a.data(), a.data() + n, out.begin());
    return out;
}

RayKind parse_kind(const std::string& k) {
    if (k == "camera") return RayKind::Camera;
    if (k == "shadow") return RayKind::Shadow;
    if (k == "reflection") return RayKind::Reflection;
    if (k == "refraction") return RayKind::Refraction;
    throw py::value_error(fmt::format("kind: '{}' (expected camera, reflection, refraction or shadow)", k));
}

/// The rays of the query arguments, checked (vectors_arg, per_ray_arg).
std::vector<Ray> rays_arg(const py::object& origins, const py::object& directions, const py::object& tmin,
                          const py::object& tmax) {
    const FloatArray o = vectors_arg(origins, "origins", -1);
    const py::ssize_t n = o.shape(0);
    const FloatArray d = vectors_arg(directions, "directions", n);
    const std::vector<float> t0 = per_ray_arg(tmin, "tmin", n, 0.f), t1 = per_ray_arg(tmax, "tmax", n, kInfinity);
    std::vector<Ray> rays(static_cast<size_t>(n));
    const float* po = o.data();
    const float* pd = d.data();
    for (size_t i = 0; i < rays.size(); ++i) {
        rays[i].org = {po[3 * i], po[3 * i + 1], po[3 * i + 2]};
        rays[i].dir = {pd[3 * i], pd[3 * i + 1], pd[3 * i + 2]};
        rays[i].tnear = t0[i];
        rays[i].tfar = t1[i];
    }
    return rays;
}

/// Runs body(begin, end) over [0, n) in chunks on every core, without the GIL.
template <typename F>
void for_chunks(size_t n, int threads, F&& body) {
    constexpr size_t kChunk = 4096;
    const size_t chunks = (n + kChunk - 1) / kChunk;
    py::gil_scoped_release release;
    WorkerPool pool(threads);
    pool.for_each(chunks, [&](size_t c, int) { body(c * kChunk, std::min(n, (c + 1) * kChunk)); });
}

// ---- render settings from keyword arguments ------------------------------------------------

/// The keyword arguments render() takes: the scene file's keys (docs/scene-format.md), so that a
/// scene file's settings fill what the caller did not pass, as the CLI's flags do.
const std::set<std::string>& render_keywords() {
    static const std::set<std::string> k{"width", "height", "camera", "aa", "aa_threshold", "aa_depth", "spp", "filter", "texture_filter",
                                         "max_depth", "min_weight", "fresnel", "specialize", "refract_thin",
                                         "mirror_cutoff", "max_exponent", "exposure", "background", "ambient",
                                         "tile_size", "threads", "crop", "aov", "accel", "robust", "progress",
                                         "env_occlusion"};
    return k;
}

Color color_arg(const py::handle& v, const char* name) {
    if (py::isinstance<py::str>(v)) return parse_color(v.cast<std::string>(), name);
    if (py::isinstance<py::float_>(v) || py::isinstance<py::int_>(v)) return Color(v.cast<float>());
    const std::vector<float> c = v.cast<std::vector<float>>();
    if (c.size() != 3) throw py::value_error(fmt::format("{}: expected a number or 3 numbers, got {}", name, c.size()));
    return {c[0], c[1], c[2]};
}

RenderSettings render_settings(const PyScene& s, const py::kwargs& kw) {
    RenderSettings rs = command_line_render_settings();
    rs.progress = false;
    for (const auto& item : kw) {
        const std::string key = item.first.cast<std::string>();
        if (!render_keywords().count(key))
            throw py::type_error(fmt::format("render() got an unexpected keyword argument '{}'", key));
        const py::handle v = item.second;
        if (key == "width") rs.width = v.cast<int>();
        else if (key == "height") rs.height = v.cast<int>();
        else if (key == "camera") rs.camera = v.cast<int>();
        else if (key == "aa") rs.aa.mode = parse_aa_mode(v.cast<std::string>());
        else if (key == "aa_threshold") rs.aa.threshold = v.cast<float>();
        else if (key == "aa_depth") rs.aa.depth = v.cast<int>();
        else if (key == "spp") rs.aa.spp = v.cast<int>();
        else if (key == "filter") rs.aa.filter = parse_pixel_filter(v.cast<std::string>());
        else if (key == "texture_filter") rs.aa.texture_filter = parse_texture_filter(v.cast<std::string>());
        else if (key == "max_depth") rs.integrator.max_depth = v.cast<int>();
        else if (key == "min_weight") rs.integrator.min_weight = v.cast<float>();
        else if (key == "fresnel") rs.integrator.fresnel = v.cast<bool>();
        else if (key == "specialize") rs.integrator.specialize = v.cast<bool>();
        else if (key == "refract_thin") rs.mapping.refract_thin = v.cast<bool>();
        else if (key == "mirror_cutoff") rs.mapping.mirror_roughness_cutoff = v.cast<float>();
        else if (key == "max_exponent") rs.mapping.max_exponent = v.cast<float>();
        else if (key == "exposure") rs.exposure = std::exp2(v.cast<float>());  // stops, as --exposure
        else if (key == "background") rs.integrator.background = color_arg(v, "background");
        else if (key == "ambient") rs.integrator.ambient = color_arg(v, "ambient");
        else if (key == "tile_size") rs.tile_size = v.cast<int>();
        else if (key == "threads") rs.threads = v.cast<int>();
        else if (key == "accel") rs.accel = v.cast<std::string>();
        else if (key == "robust") rs.robust = v.cast<bool>();
        else if (key == "progress") rs.progress = v.cast<bool>();
        else if (key == "env_occlusion") {  // "off", False or a number of directions
            if (py::isinstance<py::bool_>(v)) rs.integrator.env_occlusion = v.cast<bool>() ? kDefaultEnvOcclusion : 0;
            else if (py::isinstance<py::str>(v)) rs.integrator.env_occlusion = parse_env_occlusion(v.cast<std::string>(), "env_occlusion");
            else rs.integrator.env_occlusion = parse_env_occlusion(std::to_string(v.cast<long>()), "env_occlusion");
        }
        else if (key == "aov") {
            rs.aovs = py::isinstance<py::str>(v) ? parse_aovs({v.cast<std::string>()})
                                                : parse_aovs(v.cast<std::vector<std::string>>());
        } else if (key == "crop") {
            if (py::isinstance<py::str>(v)) {
                rs.crop = parse_crop(v.cast<std::string>());
            } else {
                const std::vector<int> c = v.cast<std::vector<int>>();
                if (c.size() != 4) throw py::value_error("crop: expected (x0, y0, x1, y1)");
                rs.crop = PixelWindow{c[0], c[1], c[2], c[3]};
            }
        }
    }
    if (!(rs.integrator.min_weight >= 0.f && rs.integrator.min_weight <= 1.f))
        throw Error(fmt::format("min_weight {} is out of range (expected 0 to 1)", rs.integrator.min_weight));
    apply_scene_settings(s.scene.settings, rs, [&](std::string_view key) { return kw.contains(std::string(key)); });
    return rs;
}

py::dict stats_dict(const RenderStats& st) {
    py::dict d;
    d["build_seconds"] = st.build_seconds;
    d["render_seconds"] = st.render_seconds;
    d["camera_rays"] = st.rays.camera;
    d["shadow_rays"] = st.rays.shadow;
    d["reflection_rays"] = st.rays.reflection;
    d["refraction_rays"] = st.rays.refraction;
    d["occlusion_rays"] = st.rays.occlusion;
    d["rays"] = st.rays.total();
    d["pixels"] = st.pixels;
    d["pixels_subdivided"] = st.pixels_subdivided;
    d["threads"] = st.threads;
    return d;
}

py::dict info_dict(const PyScene& s) {
    const Scene& sc = s.scene;
    py::dict d;
    d["path"] = s.path;
    d["meshes"] = sc.meshes.size();
    d["instances"] = sc.instances.size();
    d["triangles"] = sc.instanced_triangle_count();
    d["spheres"] = sc.spheres.size();
    d["quadrics"] = sc.quadrics.size();
    d["planes"] = sc.planes.size();
    d["materials"] = sc.materials.size();
    d["lights"] = sc.lights.size();
    d["cameras"] = sc.cameras.size();
    d["environment"] = bool(sc.environment);
    d["warnings"] = sc.warnings;
    d["text"] = describe_scene(sc);  // what `whitted info` prints
    return d;
}

OutputSettings output_settings(const std::string& view, const std::string& display, const std::string& config,
                               int bits, bool exr_float, const std::string& exr_compression,
                               const std::string& tiff_compression) {
    OutputSettings os;
    os.exr_compression = exr_compression;
    os.tiff_compression = tiff_compression;
    os.color.view = view;
    os.color.display = display;
    os.color.config = config;
    os.bits = bits;
    os.exr_half = !exr_float;
    return os;
}

}  // namespace
}  // namespace whitted

PYBIND11_MODULE(whitted, m) {
    using namespace whitted;
    PYBIND11_NUMPY_DTYPE(Hit, t, u, v, prim, geom, inst);
    m.doc() = "whitted: a Whitted-style (1980) recursive ray tracer for glTF 2.0 scenes (docs/python.md)";
    m.attr("__version__") = version();
    // whitted.Error: the one-line message, and where: .file, .pointer (JSON pointer), .line.
    static py::exception<Error> error(m, "Error", PyExc_RuntimeError);
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const Error& e) {
            py::object instance = py::reinterpret_borrow<py::object>(error.ptr())(e.what());
            instance.attr("file") = e.location().file;
            instance.attr("pointer") = e.location().pointer;
            instance.attr("line") = e.location().line;
            PyErr_SetObject(error.ptr(), instance.ptr());
        }
    });
    m.attr("accelerators") = accelerator_names();
    m.def("_data_file", &data_file, py::arg("relative"), "Where the module finds a data file (tests)");
    // A library speaks only when something is wrong; set_log_level("info") for what `render` logs.
    set_log_level(LogLevel::Warning);
    m.def(
        "set_log_level", [](const std::string& level) { set_log_level(parse_log_level(level)); }, py::arg("level"),
        "Messages printed to stderr: debug, info, warning (the module's default), error, off");

    py::class_<PyScene, std::shared_ptr<PyScene>>(m, "Scene", "A loaded scene (whitted.load)")
        .def_readonly("path", &PyScene::path)
        .def("info", &info_dict, "What `whitted info` prints, as a dict (its text under 'text')")
        .def(
            "intersect",
            [](PyScene& s, const py::object& origins, const py::object& directions, const py::object& tmax,
               const py::object& tmin, const std::string& accel, const std::string& kind, int threads) {
                const std::vector<Ray> rays = rays_arg(origins, directions, tmin, tmax);
                const auto n = py::ssize_t(rays.size());
                const Accelerator& a = *s.queries_for(accel).accel;
                const RayKind k = parse_kind(kind);
                py::array_t<Hit> hits(n);
                Hit* out = hits.mutable_data();
                for_chunks(size_t(n), threads, [&](size_t b, size_t e) {
                    for (size_t i = b; i < e; ++i) out[i] = a.intersect(rays[i], k);
                });
                return hits;
            },
            py::arg("origins"), py::arg("directions"), py::arg("tmax") = py::none(), py::arg("tmin") = py::none(),
            py::arg("accel") = "embree", py::arg("kind") = "camera", py::arg("threads") = 0,
            "Closest hits of rays (origins, directions: (N, 3), float32 or float64) through the accelerator "
            "`accel` (whitted.accelerators, with options: 'bvh:precision=double'): a structured array of N "
            "(t, u, v, prim, geom, inst); misses have t = inf and geom = 2**32 - 1. kind='camera' culls the back "
            "faces of single-sided materials; 'reflection' does not.")
        .def(
            "transmittance",
            [](PyScene& s, const py::object& origins, const py::object& directions, const py::object& tmax,
               const py::object& tmin, const std::string& accel, int threads) {
                const std::vector<Ray> rays = rays_arg(origins, directions, tmin, tmax);
                const auto n = py::ssize_t(rays.size());
                const Accelerator& a = *s.queries_for(accel).accel;
                py::array_t<float> t({n, py::ssize_t(3)});
                float* out = t.mutable_data();
                for_chunks(size_t(n), threads, [&](size_t b, size_t e) {
                    for (size_t i = b; i < e; ++i) {
                        const Color c = a.transmittance(rays[i]);
                        out[3 * i] = c.x;
                        out[3 * i + 1] = c.y;
                        out[3 * i + 2] = c.z;
                    }
                });
                return t;
            },
            py::arg("origins"), py::arg("directions"), py::arg("tmax") = py::none(), py::arg("tmin") = py::none(),
            py::arg("accel") = "embree", py::arg("threads") = 0,
            "Shadow query: the (N, 3) transmittance along each ray over [tmin, tmax] (0 behind opaque surfaces, "
            "1 unoccluded, Kt products through transparent ones)");

    py::class_<PyImage>(m, "Image", "A rendered film: beauty and AOVs as arrays that share its memory")
        .def_property_readonly("beauty", &beauty_of, "float32 (H, W, 3), scene-linear Rec.709")
        .def_property_readonly("aov", &aovs_of, "dict of the AOVs asked for: depth, prim_id, inst_id, aa_samples "
                                                "(H, W); normal, albedo (H, W, 3)")
        .def_property_readonly("width", [](const PyImage& i) { return i.film->window.width(); })
        .def_property_readonly("height", [](const PyImage& i) { return i.film->window.height(); })
        .def_property_readonly("window", [](const PyImage& i) {
            const PixelWindow& w = i.film->window;
            return py::make_tuple(w.x0, w.y0, w.x1, w.y1);
        }, "(x0, y0, x1, y1) of the full image (the crop)")
        .def_property_readonly("stats", [](const PyImage& i) { return stats_dict(i.stats); });

    m.def(
        "load",
        [](const std::string& path, int scene_index, const std::string& environment,
           std::optional<float> env_rotate, std::optional<float> env_exposure, int env_lights, bool no_environment,
           bool default_light, bool default_camera, bool allow_outside_uris, double max_memory_gb, double time,
           const std::string& animation, bool loop, const std::string& variant) {
            ImportOptions io;
            io.variant = variant;
            check_animation_time(time, "time");
            io.time = time;
            io.animation = animation;
            io.loop = loop;
            io.scene_index = scene_index;
            io.environment = environment;
            io.environment_rotation = env_rotate;
            io.environment_exposure = env_exposure;
            io.environment_lights = env_lights;
            io.no_environment = no_environment;
            io.add_default_light = default_light;
            io.add_default_camera = default_camera;
            io.allow_outside_uris = allow_outside_uris;
            io.max_memory = size_t(max_memory_gb * double(size_t(1) << 30));
            auto s = std::make_shared<PyScene>();
            s->path = path;
            {
                py::gil_scoped_release release;
                s->scene = load_scene(path, io);
            }
            return s;
        },
        py::arg("path"), py::arg("scene_index") = -1, py::arg("environment") = "", py::arg("env_rotate") = py::none(),
        py::arg("env_exposure") = py::none(), py::arg("env_lights") = kDefaultEnvironmentLights,
        py::arg("no_environment") = false, py::arg("default_light") = true, py::arg("default_camera") = true,
        py::arg("allow_outside_uris") = false, py::arg("max_memory_gb") = 8.0, py::arg("time") = 0.0,
        py::arg("animation") = "all", py::arg("loop") = false, py::arg("variant") = "",
        "Loads a .gltf, .glb or .json scene file (the options of `whitted render`'s import flags; an animated "
        "glTF posed at `time` seconds under `animation`: 'all', a name or indices '0,2'; `variant`: a "
        "KHR_materials_variants variant by name); raises "
        "whitted.Error naming the file and the problem");

    m.def(
        "render",
        [](const std::shared_ptr<PyScene>& s, const py::kwargs& kw) {
            const RenderSettings rs = render_settings(*s, kw);
            PyImage img;
            {
                py::gil_scoped_release release;
                const Renderer renderer(s->scene, rs);
                img.film = std::make_shared<Film>(renderer.render(&img.stats));
            }
            return img;
        },
        py::arg("scene"),
        "Renders the scene with the settings of `whitted render` (keyword arguments named as the scene file's "
        "settings: width, height, camera, aa, aa_threshold, aa_depth, spp, filter, texture_filter, max_depth, min_weight, "
        "fresnel, specialize, refract_thin, mirror_cutoff, max_exponent, exposure (stops), background, ambient, env_occlusion, tile_size, "
        "threads, crop, aov, accel, robust, progress); the scene file's settings fill what is not given");

    m.def(
        "display",
        [](const py::object& beauty, const std::string& view, const std::string& display, const std::string& config,
           int bits) {
            const py::array raw = py::array::ensure(beauty);
            if (!raw || raw.ndim() != 3 || raw.shape(2) != 3)
                throw py::value_error(fmt::format("beauty: expected shape (H, W, 3), got {}",
                                                  raw ? shape_text(raw) : std::string("a non-array")));
            const FloatArray a = FloatArray::ensure(raw);
            const size_t n = size_t(a.shape(0) * a.shape(1));
            const std::span<const Color> pixels(reinterpret_cast<const Color*>(a.data()), n);
            ColorSettings cs;
            cs.view = view;
            cs.display = display;
            cs.config = config;
            const DisplayTransform transform(cs);
            const std::vector<py::ssize_t> shape{a.shape(0), a.shape(1), 3};
            py::array out = bits == 16 ? py::array(py::array_t<uint16_t>(shape)) : py::array(py::array_t<uint8_t>(shape));
            display_codes(pixels, transform, bits,
                          std::span<uint8_t>(static_cast<uint8_t*>(out.mutable_data()), size_t(out.nbytes())));
            return out;
        },
        py::arg("beauty"), py::arg("view") = "Standard", py::arg("display") = "", py::arg("ocio_config") = "",
        py::arg("bits") = 8,
        "Scene-linear (H, W, 3) to display codes through OCIO, exactly as `render` writes PNGs: uint8 (bits=8) or "
        "uint16 (bits=16)");

    m.def(
        "write",
        [](const PyImage& img, const std::string& path, const std::string& view, const std::string& display,
           const std::string& config, int bits, bool exr_float, const std::string& exr_compression,
           const std::string& tiff_compression) {
            py::gil_scoped_release release;
            write_image(*img.film, path,
                        output_settings(view, display, config, bits, exr_float, exr_compression, tiff_compression));
        },
        py::arg("image"), py::arg("path"), py::arg("view") = "Standard", py::arg("display") = "",
        py::arg("ocio_config") = "", py::arg("bits") = 0, py::arg("exr_float") = false,
        py::arg("exr_compression") = "zip", py::arg("tiff_compression") = "zip",
        "Writes the image as `render` does: .exr scene-linear with the AOVs, .png/.jpg/.tif through OCIO");

    m.def(
        "read_image",
        [](const std::string& path) {
            int w = 0, h = 0;
            std::vector<float> rgb = read_image_rgb(path, w, h);
            py::array_t<float> out({py::ssize_t(h), py::ssize_t(w), py::ssize_t(3)});
            std::copy(rgb.begin(), rgb.end(), out.mutable_data());
            return out;
        },
        py::arg("path"), "An image file's RGB as float32 (H, W, 3), as stored (8-bit PNG: code / 255)");
}
