// Image tests: real assets rendered and compared with reference EXRs through OIIO's compare
// (fail above a count of pixels off by more than a threshold, like Embree's --compare-threshold).
// Each case also proves its threshold can fail: the same render shifted by one pixel (what a
// one-pixel camera shift produces) must be rejected.
//
// Regenerate the references after an intended change:
//   WHITTED_UPDATE_REFERENCES=1 ctest -R ReferenceImages   (writes tests/data/references/*.exr)
#include <gtest/gtest.h>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "importers/scene_loader.h"
#include "integrator/render.h"
#include "output/image_output.h"

namespace whitted {
namespace {

namespace fs = std::filesystem;

struct ImageCase {
    std::string name;         ///< reference file stem
    std::string asset;        ///< path below assets/
    int width = 160;
    int height = 0;
    int camera = 0;
    bool refract_thin = false;
    bool scene_settings = false;  ///< a scene file: apply its render settings, then the size above
    bool no_environment = false;  ///< the default light instead of the default studio environment
    std::string environment{};    ///< an environment to light it with (ImportOptions::environment)
};

std::ostream& operator<<(std::ostream& os, const ImageCase& c) { return os << c.name; }

/// A pixel fails when any channel differs by more than kFailThreshold (linear, absolute) and
/// the case fails when more than kMaxFailFraction of the pixels do.
constexpr float kFailThreshold = 0.02f;
constexpr double kMaxFailFraction = 0.002;

OIIO::ImageBuf to_imagebuf(const Film& film) {
    OIIO::ImageSpec spec(film.width(), film.height(), 3, OIIO::TypeDesc::FLOAT);
    OIIO::ImageBuf buf(spec);
    for (int y = 0; y < film.height(); ++y)
        for (int x = 0; x < film.width(); ++x) {
            const Color& c = film.beauty[size_t(y) * size_t(film.width()) + size_t(x)];
            const float v[3] = {c.x, c.y, c.z};
            buf.setpixel(x, y, v);
        }
    return buf;
}

Film render_case(const ImageCase& c) {
    ImportOptions io;
    io.no_environment = c.no_environment;
    io.environment = c.environment;
    Scene scene = load_scene(std::string(WHITTED_ASSETS_DIR) + "/" + c.asset, io);
    RenderSettings rs;
    if (c.scene_settings) apply_scene_settings(scene.settings, rs);
    rs.width = c.width;
    rs.height = c.height;
    if (c.scene_settings && c.height == 0 && scene.settings.width && scene.settings.height)
        rs.height = int(std::lround(double(c.width) * *scene.settings.height / *scene.settings.width));
    rs.camera = c.camera;
    rs.mapping.refract_thin = c.refract_thin;
    return Renderer(scene, rs).render();
}

class ReferenceImages : public ::testing::TestWithParam<ImageCase> {};

TEST_P(ReferenceImages, MatchesReference) {
    const ImageCase& c = GetParam();
    const fs::path ref = fs::path(WHITTED_TEST_DATA_DIR) / "references" / (c.name + ".exr");
    Film film = render_case(c);
    OIIO::ImageBuf img = to_imagebuf(film);

    const char* update = std::getenv("WHITTED_UPDATE_REFERENCES");
    if (update && std::string(update) == "1") {
        fs::create_directories(ref.parent_path());
        OutputSettings os;
        os.exr_half = false;
        write_image(film, ref.string(), os);
        GTEST_SKIP() << "reference written: " << ref;  // never counted as a pass in CI (no env var there)
    }
    ASSERT_TRUE(fs::exists(ref)) << "missing reference " << ref << " (run with WHITTED_UPDATE_REFERENCES=1)";
    OIIO::ImageBuf expected(ref.string());
    ASSERT_TRUE(expected.read(0, 0, true, OIIO::TypeDesc::FLOAT)) << expected.geterror();
    ASSERT_EQ(expected.spec().width, img.spec().width);
    ASSERT_EQ(expected.spec().height, img.spec().height);

    const double pixels = double(img.spec().width) * img.spec().height;
    auto result = OIIO::ImageBufAlgo::compare(img, expected, kFailThreshold, kFailThreshold * 0.5f);
    EXPECT_LE(double(result.nfail), kMaxFailFraction * pixels)
        << c.name << ": " << result.nfail << " pixels off by more than " << kFailThreshold << " (max error "
        << result.maxerror << " at " << result.maxx << "," << result.maxy << ")";

    // Test of the test: a one-pixel shift of the same image must fail the same threshold.
    OIIO::ImageBuf shifted;
    ASSERT_TRUE(OIIO::ImageBufAlgo::paste(shifted, 1, 0, 0, 0, img));
    OIIO::ImageBuf shifted_cropped = OIIO::ImageBufAlgo::cut(shifted, img.roi());
    auto shifted_result = OIIO::ImageBufAlgo::compare(shifted_cropped, expected, kFailThreshold, kFailThreshold * 0.5f);
    EXPECT_GT(double(shifted_result.nfail), kMaxFailFraction * pixels)
        << c.name << ": a one-pixel shift passes the threshold, so the test could not catch it";
}

INSTANTIATE_TEST_SUITE_P(
    RealAssets, ReferenceImages,
    ::testing::Values(ImageCase{"box", "gltf/Box/glTF-Binary/Box.glb", 160, 0, 0, false, false, true},
                      ImageCase{"duck", "gltf/Duck/glTF-Binary/Duck.glb", 160, 0, 0, false, false, true},
                      ImageCase{"duck_studio", "gltf/Duck/glTF-Binary/Duck.glb"},
                      ImageCase{"box_courtyard", "gltf/Box/glTF-Binary/Box.glb", 160, 0, 0, false, false, false, "courtyard"},
                      ImageCase{"lamp", "gltf/LightsPunctualLamp/glTF/LightsPunctualLamp.gltf"},
                      ImageCase{"hurricane", "gltf/GlassHurricaneCandleHolder/glTF-Binary/GlassHurricaneCandleHolder.glb",
                                160, 0, 0, false, false, true},
                      ImageCase{"hurricane_studio",
                                "gltf/GlassHurricaneCandleHolder/glTF-Binary/GlassHurricaneCandleHolder.glb"},
                      ImageCase{"default_scene", "scenes/default.glb"},
                      ImageCase{"whitted1980", "scenes/whitted1980.json", 160, 0, 0, false, true},
                      ImageCase{"transparent_shadows", "scenes/transparent_shadows.json", 160, 0, 0, false, true},
                      ImageCase{"glass_mirror_room", "scenes/glass_mirror_room.json", 160, 0, 0, false, true},
                      ImageCase{"quadrics", "scenes/quadrics.json", 160, 0, 0, false, true}),
    [](const ::testing::TestParamInfo<ImageCase>& info) { return info.param.name; });

}  // namespace
}  // namespace whitted
