// `whitted-reference`: renders a scene with the reference renderer (reference/reference_renderer.h)
// into a float EXR, for comparison with `whitted render --aa center --min-weight 0
// --texture-filter none --exr-float` (docs/integrator.md, "The reference renderer").
#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include "importers/scene_loader.h"
#include "reference/reference_renderer.h"
#include "core/error.h"
#include "film/film.h"
#include "output/image_output.h"

using namespace whitted;

int main(int argc, char** argv) {
    CLI::App app{"whitted-reference: Whitted (1980) in plain double precision, one ray per pixel centre, brute force"};
    std::string input, output;
    RenderSettings rs;  // the library defaults: centre sampling, min weight 0
    rs.aa.texture_filter = TextureFilter::None;
    ImportOptions io;
    int threads = 0;
    app.add_option("scene", input, "Scene file (.gltf, .glb, .json)")->required();
    app.add_option("-o,--output", output, "Output image: a .exr file (32-bit float, scene-linear)")->required();
    app.add_option("--width", rs.width, "Image width in pixels (0 = from the height and the camera's aspect)");
    app.add_option("--height", rs.height, "Image height in pixels (0 = from the width and the camera's aspect)");
    app.add_option("--camera", rs.camera, "Camera index")->capture_default_str();
    app.add_option("--scene-index", io.scene_index, "glTF scene index (-1 = the file's default scene)");
    app.add_option("--max-depth", rs.integrator.max_depth, "Maximum depth of the ray tree")
        ->check(CLI::Range(0, 64))->capture_default_str();
    app.add_option_function<std::string>(
        "--background", [&](const std::string& t) { rs.integrator.background = parse_color(t, "--background"); },
        "Radiance of rays that hit nothing: r,g,b or gray (linear)");
    app.add_option_function<std::string>(
        "--ambient", [&](const std::string& t) { rs.integrator.ambient = parse_color(t, "--ambient"); },
        "Ambient light Ia: r,g,b or gray (linear)");
    app.add_option_function<float>("--exposure", [&](float stops) { rs.exposure = std::exp2(stops); },
                                   "Exposure in stops: radiance is scaled by 2^exposure");
    app.add_flag("--fresnel", rs.integrator.fresnel, "Schlick-weighted reflection and transmission");
    app.add_flag("--refract-thin", rs.mapping.refract_thin, "Refract through transmissive glTF materials without a volume");
    app.add_option("--mirror-cutoff", rs.mapping.mirror_roughness_cutoff, "glTF roughness at which kr has faded to 0");
    app.add_flag("--no-environment", io.no_environment, "No environment, whatever the scene file names");
    app.add_option("--threads", threads, "Threads (0 = all cores); the image does not depend on it");
    // Accepted so that the production command line can be repeated; other values are refused.
    app.add_option_function<std::string>("--aa", [&](const std::string& n) { rs.aa.mode = parse_aa_mode(n); },
                                         "Anti-aliasing: center only");
    app.add_option("--min-weight", rs.integrator.min_weight, "Adaptive tree depth: 0 only");
    app.add_option_function<std::string>(
        "--texture-filter", [&](const std::string& n) { rs.aa.texture_filter = parse_texture_filter(n); },
        "Texture filtering: none only");
    bool exr_float = true;
    app.add_flag("--exr-float", exr_float, "EXR output is always 32-bit float (accepted for symmetry with `whitted render`)");
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e);
    }

    try {
        if (!output.ends_with(".exr")) throw Error(fmt::format("-o {}: the reference writes .exr files only", output));
        // A glTF file without lights is lit by the bundled environment unless --no-environment;
        // the reference refuses environments, so it asks for the documented default light instead.
        if (io.no_environment) io.default_environment = false;
        Scene scene = load_scene(input, io);
        // The scene file's settings fill what the flags did not set; sampling, the ray-tree cutoff
        // and texture filtering are the reference's own.
        apply_scene_settings(scene.settings, rs, [&](std::string_view key) {
            if (key == "aa" || key == "min_weight") return true;
            const CLI::Option* option = app.get_option_no_throw(setting_flag(key));
            return option != nullptr && option->count() > 0;
        });
        const auto start = std::chrono::steady_clock::now();
        const ReferenceImage img = render_reference(scene, rs, threads);
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

        Film film(img.width, img.height, PixelWindow{0, 0, img.width, img.height}, AovSet{});
        for (size_t i = 0; i < img.radiance.size(); ++i) film.beauty[i] = Color(img.radiance[i]);
        OutputSettings os;
        os.exr_half = false;
        os.metadata["whitted:renderer"] = "reference";
        os.metadata["whitted:version"] = WHITTED_VERSION;
        write_image(film, output, os);
        std::fprintf(stderr, "whitted-reference: wrote %s (%dx%d) in %.2f s\n", output.c_str(), img.width, img.height,
                     seconds);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "whitted-reference: error: %s\n", e.what());
        return 1;
    }
    return 0;
}
