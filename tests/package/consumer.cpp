// Uses the stable surface of <whitted/whitted.h> from an installed package: load a scene, render
// it into a Film, write it through OCIO, trace rays through two accelerators and, when given a
// third argument, read that image back (a PNG goes through the installed image module).
#include <whitted/whitted.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

int main(int argc, char** argv) {
    if (argc != 3 && argc != 4) {
        std::fprintf(stderr, "usage: consumer SCENE OUT.png [IMAGE.png]\n");
        return 2;
    }
    try {
        whitted::Scene scene = whitted::load_scene(argv[1]);
        whitted::RenderSettings rs = whitted::command_line_render_settings();
        rs.width = 48;
        rs.progress = false;
        const whitted::Renderer renderer(scene, rs);
        whitted::RenderStats stats;
        const whitted::Film film = renderer.render(&stats);
        whitted::write_image(film, argv[2], {});
        // The centre pixel's camera ray through the renderer's accelerator and a second one.
        const whitted::CameraModel camera(scene.cameras[0], film.width(), film.height());
        const whitted::Ray ray = camera.generate(0.5 * film.width(), 0.5 * film.height());
        const whitted::Hit a = renderer.accelerator().intersect(ray, whitted::RayKind::Camera);
        const auto bvh = whitted::create_accelerator("bvh", scene, renderer.view());
        const whitted::Hit b = bvh->intersect(ray, whitted::RayKind::Camera);
        std::printf("OCIO config: %s\n", whitted::bundled_ocio_config().c_str());
        std::printf("whitted %s: %dx%d, %llu rays, centre hit t=%g (embree) t=%g (bvh)\n", whitted::version(),
                    film.width(), film.height(), (unsigned long long)stats.rays.total(), a.t, b.t);
        if (!a.valid() || !b.valid() || std::fabs(a.t - b.t) > 1e-3f * a.t) return 1;
        if (argc == 4) {
            int w = 0, h = 0;
            const std::vector<float> rgb = whitted::read_image_rgb(argv[3], w, h);
            std::printf("read %s: %dx%d\n", argv[3], w, h);
            if (w <= 0 || h <= 0 || rgb.size() != size_t(w) * size_t(h) * 3) return 1;
        }
        try {
            whitted::load_scene(std::string(argv[1]) + ".missing.glb");
            return 1;
        } catch (const whitted::Error&) {
        }
        return 0;
    } catch (const whitted::Error& e) {
        std::fprintf(stderr, "consumer: %s\n", e.what());
        return 1;
    }
}
