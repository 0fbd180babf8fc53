// Unit tests for color-managed image output: the bundled OCIO config and its views, config
// resolution ($OCIO), EXR layout (data window, AOVs, metadata), 8/16-bit quantization,
// NaN/inf handling and atomic writes.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <unistd.h>

#include <OpenColorIO/OpenColorIO.h>
#include <OpenImageIO/imageio.h>
#include <fmt/format.h>

#include "core/error.h"
#include "output/image_output.h"

namespace fs = std::filesystem;
using namespace whitted;

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

/// Reference sRGB encoding (IEC 61966-2-1), independent of OCIO.
double srgb_encode(double v) { return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055; }

/// Expected 8/16-bit code of a linear value through the Standard view (clamped, rounded).
int expected_code(double linear, int max_code) {
    double e = std::clamp(srgb_encode(std::max(linear, 0.0)), 0.0, 1.0);
    return int(std::lround(e * max_code));
}

/// Runs `f` and returns the whitted::Error message it throws ("" if it does not throw).
template <typename F>
std::string error_of(F&& f) {
    try {
        f();
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

/// A full-frame film with only beauty.
Film make_film(int w, int h, AovSet aovs = {}) { return Film(w, h, PixelWindow{0, 0, w, h}, aovs); }

/// All channels of an image through OIIO, as `type`, plus its spec.
template <typename T>
std::vector<T> read_channels(const std::string& path, int chbegin, int chend, OIIO::TypeDesc type,
                             OIIO::ImageSpec* spec_out = nullptr) {
    auto in = OIIO::ImageInput::open(path);
    if (!in) throw std::runtime_error(OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    if (spec_out) *spec_out = spec;
    std::vector<T> data(size_t(spec.width) * size_t(spec.height) * size_t(chend - chbegin));
    if (!in->read_image(0, 0, chbegin, chend, type, data.data())) throw std::runtime_error(in->geterror());
    return data;
}

OIIO::ImageSpec read_spec(const std::string& path) {
    auto in = OIIO::ImageInput::open(path);
    if (!in) throw std::runtime_error(OIIO::geterror());
    return in->spec();
}

int channel_index(const OIIO::ImageSpec& spec, const std::string& name) {
    for (int c = 0; c < spec.nchannels; ++c)
        if (spec.channel_name(c) == name) return c;
    return -1;
}

/// Each test gets a fresh scratch directory and a clean $OCIO, both restored afterwards.
class ImageOutputTest : public ::testing::Test {
protected:
    void SetUp() override {
        if (const char* env = std::getenv("OCIO")) m_saved_ocio = env;
        ::unsetenv("OCIO");
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        m_dir = fs::temp_directory_path() /
                fmt::format("whitted_test_image_output_{}_{}", long(::getpid()), info->name());
        fs::remove_all(m_dir);
        fs::create_directories(m_dir);
    }
    void TearDown() override {
        if (m_saved_ocio)
            ::setenv("OCIO", m_saved_ocio->c_str(), 1);
        else
            ::unsetenv("OCIO");
        std::error_code ec;
        fs::remove_all(m_dir, ec);
    }
    std::string path(const std::string& name) const { return (m_dir / name).string(); }
    /// Names of the files in the scratch directory, sorted.
    std::vector<std::string> listing() const {
        std::vector<std::string> names;
        for (const auto& entry : fs::directory_iterator(m_dir)) names.push_back(entry.path().filename().string());
        std::sort(names.begin(), names.end());
        return names;
    }

    fs::path m_dir;
    std::optional<std::string> m_saved_ocio;
};

ColorSettings view_settings(const std::string& view) {
    ColorSettings s;
    s.view = view;
    return s;
}

}  // namespace

// ---- the bundled config ----------------------------------------------------------------------

TEST_F(ImageOutputTest, BundledConfigIsFoundAndLoads) {
    const std::string bundled = bundled_ocio_config();
    EXPECT_TRUE(fs::is_regular_file(bundled)) << bundled;
    EXPECT_TRUE(bundled.ends_with("assets/ocio/config.ocio")) << bundled;

    DisplayTransform t(ColorSettings{});
    EXPECT_EQ(t.config_path(), bundled);
    EXPECT_EQ(t.display(), "sRGB");
    EXPECT_EQ(t.view(), "Standard");
}

TEST_F(ImageOutputTest, EmptyViewMeansTheDisplayDefault) {
    DisplayTransform t(view_settings(""));
    EXPECT_EQ(t.view(), "Standard");
}

TEST_F(ImageOutputTest, StandardViewIsTheSrgbCurve) {
    DisplayTransform t(view_settings("Standard"));
    Color grey = t.apply(Color(0.18f));
    EXPECT_NEAR(grey.x, 0.4614f, 1e-3f);
    EXPECT_NEAR(grey.y, 0.4614f, 1e-3f);
    EXPECT_NEAR(grey.z, 0.4614f, 1e-3f);
    // Grey stays grey: the view's Rec.709 -> XYZ matrix inverts the display's XYZ -> Rec.709.
    EXPECT_NEAR(grey.x, grey.y, 1e-5f);
    EXPECT_NEAR(grey.z, grey.y, 1e-5f);

    Color c = t.apply(Color(0.5f, 0.25f, 0.1f));
    EXPECT_NEAR(c.x, 0.7354f, 1e-3f);
    EXPECT_NEAR(c.y, 0.5371f, 1e-3f);
    EXPECT_NEAR(c.z, 0.3492f, 1e-3f);

    // The whole curve, including the linear toe, against an independent implementation.
    for (double v : {0.0, 0.001, 0.0031308, 0.01, 0.1, 0.5, 0.9, 1.0}) {
        Color e = t.apply(Color(float(v)));
        EXPECT_NEAR(e.y, srgb_encode(v), 2e-4) << "linear " << v;
    }
}

TEST_F(ImageOutputTest, AcesViewMatchesReference) {
    DisplayTransform t(view_settings("ACES 1.0 SDR-video"));
    Color grey = t.apply(Color(0.18f));
    EXPECT_NEAR(grey.x, 0.3560f, 1e-3f);
    EXPECT_NEAR(grey.y, 0.3560f, 1e-3f);
    EXPECT_NEAR(grey.z, 0.3560f, 1e-3f);
    // Tone mapping: much brighter than 1 still lands at or below display white.
    Color bright = t.apply(Color(16.f));
    EXPECT_LE(bright.y, 1.001f);
    EXPECT_GT(bright.y, 0.9f);
}

TEST_F(ImageOutputTest, RawViewIsIdentity) {
    DisplayTransform t(view_settings("Raw"));
    for (Color c : {Color(0.18f), Color(0.5f, 0.25f, 0.1f), Color(-1.f, 7.5f, 1e-6f)}) {
        Color r = t.apply(c);
        EXPECT_EQ(r.x, c.x);
        EXPECT_EQ(r.y, c.y);
        EXPECT_EQ(r.z, c.z);
    }
}

TEST_F(ImageOutputTest, BulkApplyMatchesSinglePixelsAcrossThreads) {
    DisplayTransform t(view_settings("ACES 1.0 SDR-video"));
    // More pixels than one internal chunk, so the chunking is exercised too.
    const size_t n = 10000;
    std::vector<float> input(3 * n);
    for (size_t i = 0; i < input.size(); ++i) input[i] = float(i % 997) / 300.f;

    std::vector<float> expected = input;
    for (size_t i = 0; i < n; ++i) {
        Color c = t.apply(Color(expected[3 * i], expected[3 * i + 1], expected[3 * i + 2]));
        expected[3 * i] = c.x, expected[3 * i + 1] = c.y, expected[3 * i + 2] = c.z;
    }

    // The same transform applied concurrently from several threads gives the same answer.
    std::vector<std::vector<float>> results(4, input);
    std::vector<std::thread> threads;
    for (auto& r : results) threads.emplace_back([&t, &r, n] { t.apply(r.data(), n); });
    for (auto& th : threads) th.join();
    for (const auto& r : results)
        for (size_t i = 0; i < r.size(); ++i) ASSERT_NEAR(r[i], expected[i], 1e-6f) << "value " << i;
}

TEST_F(ImageOutputTest, ConfigColorSpacesConvertAsDocumented) {
    namespace OCIO = OCIO_NAMESPACE;
    OCIO::ConstConfigRcPtr config = OCIO::Config::CreateFromFile(bundled_ocio_config().c_str());
    auto convert = [&](const char* dst, float v) {
        std::array<float, 3> p{v, v, v};
        config->getProcessor(OCIO::ROLE_SCENE_LINEAR, dst)->getDefaultCPUProcessor()->applyRGB(p.data());
        return p;
    };
    EXPECT_NEAR(convert("sRGB - Texture", 0.18f)[1], 0.4614f, 1e-3f);
    EXPECT_NEAR(convert("ACES2065-1", 0.18f)[1], 0.18f, 1e-5f);   // Bradford keeps neutrals neutral
    EXPECT_NEAR(convert("ACEScct", 0.18f)[1], 0.4136f, 1e-3f);    // ACEScct of mid grey
    EXPECT_EQ(convert("Raw", 0.18f)[1], 0.18f);
    EXPECT_STREQ(config->getColorSpace(OCIO::ROLE_DATA)->getName(), "Raw");
}

// ---- config resolution and errors ------------------------------------------------------------

TEST_F(ImageOutputTest, UnknownViewNamesItAndListsValidViews) {
    std::string msg = error_of([] { DisplayTransform t(view_settings("Filmic")); });
    EXPECT_NE(msg.find("'Filmic'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("Standard, ACES 1.0 SDR-video, Raw"), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "one line: " << msg;
}

TEST_F(ImageOutputTest, UnknownDisplayNamesItAndListsValidDisplays) {
    ColorSettings s;
    s.display = "DCI-P3";
    std::string msg = error_of([&] { DisplayTransform t(s); });
    EXPECT_NE(msg.find("'DCI-P3'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("valid displays: sRGB"), std::string::npos) << msg;
}

TEST_F(ImageOutputTest, MissingOrBrokenConfigNamesThePath) {
    ColorSettings s;
    s.config = path("missing.ocio");
    std::string msg = error_of([&] { DisplayTransform t(s); });
    EXPECT_NE(msg.find(s.config), std::string::npos) << msg;

    s.config = path("broken.ocio");
    std::ofstream(s.config) << "ocio_profile_version: 2\nroles: [this is: not valid\n";
    msg = error_of([&] { DisplayTransform t(s); });
    EXPECT_NE(msg.find(s.config), std::string::npos) << msg;
}

TEST_F(ImageOutputTest, OcioEnvironmentVariableIsHonoured) {
    // A nonexistent $OCIO is an error naming that path.
    const std::string missing = path("nowhere/config.ocio");
    ::setenv("OCIO", missing.c_str(), 1);
    std::string msg = error_of([] { DisplayTransform t(ColorSettings{}); });
    EXPECT_NE(msg.find(missing), std::string::npos) << msg;
    EXPECT_NE(msg.find("$OCIO"), std::string::npos) << msg;
    // ... also when it surfaces through write_image, which adds the image path.
    const std::string png = path("needs_ocio.png");
    msg = error_of([&] { write_image(make_film(2, 2), png, OutputSettings{}); });
    EXPECT_NE(msg.find(png), std::string::npos) << msg;
    EXPECT_NE(msg.find(missing), std::string::npos) << msg;
    EXPECT_FALSE(fs::exists(png));

    // $OCIO pointing at the bundled config works.
    ::setenv("OCIO", bundled_ocio_config().c_str(), 1);
    EXPECT_EQ(DisplayTransform(ColorSettings{}).config_path(), bundled_ocio_config());

    // A copy whose display has another name proves the file really comes from $OCIO.
    std::ifstream src(bundled_ocio_config());
    std::stringstream text;
    text << src.rdbuf();
    std::string config = text.str();
    for (auto [from, to] : {std::pair<std::string, std::string>{"\n  sRGB:\n", "\n  Test Monitor:\n"},
                            {"active_displays: [sRGB]", "active_displays: [Test Monitor]"}}) {
        size_t at = config.find(from);
        ASSERT_NE(at, std::string::npos) << from;
        config.replace(at, from.size(), to);
    }
    const std::string copy = path("renamed.ocio");
    std::ofstream(copy) << config;
    ::setenv("OCIO", copy.c_str(), 1);
    DisplayTransform t(ColorSettings{});
    EXPECT_EQ(t.config_path(), copy);
    EXPECT_EQ(t.display(), "Test Monitor");
    EXPECT_NEAR(t.apply(Color(0.18f)).y, 0.4614f, 1e-3f);

    // An explicit config wins over $OCIO.
    ColorSettings explicit_config;
    explicit_config.config = bundled_ocio_config();
    EXPECT_EQ(DisplayTransform(explicit_config).display(), "sRGB");

    // An empty $OCIO counts as unset.
    ::setenv("OCIO", "", 1);
    EXPECT_EQ(DisplayTransform(ColorSettings{}).config_path(), bundled_ocio_config());
}

// ---- EXR -------------------------------------------------------------------------------------

namespace {

/// A 7x5 image cropped to [2, 6) x [1, 4) with every AOV and distinctive values.
Film make_aov_film() {
    AovSet aovs;
    aovs.depth = aovs.normal = aovs.albedo = aovs.prim_id = aovs.inst_id = true;
    Film film(7, 5, PixelWindow{2, 1, 6, 4}, aovs);
    for (size_t i = 0; i < film.beauty.size(); ++i) {
        float f = float(i);
        film.beauty[i] = Color(0.1f + f / 7.f, 1.f / (f + 3.f), 123.456f * f + 1e-3f);
        film.depth[i] = i == 3 ? kInf : 1.5f + f;
        film.normal[i] = Vec3f(-0.25f * f, 0.5f, 1.f / (f + 1.f));
        film.albedo[i] = Color(0.01f * f, 0.5f, 0.9f);
        film.prim_id[i] = i == 5 ? 0xffffffffu : 16777217u + uint32_t(i);  // not representable as float
        film.inst_id[i] = uint32_t(i) * 3u;
    }
    return film;
}

}  // namespace

// --exr-compression: every lossless method the flag accepts writes the same float values back,
// under the name asked for; a method it does not accept is one error naming the file, and writes
// nothing.
TEST_F(ImageOutputTest, ExrCompressionsAreLosslessAndNamedInTheHeader) {
    const Film film = make_aov_film();
    for (const char* method : {"none", "rle", "zips", "zips:9", "zip", "zip:6", "piz"}) {
        OutputSettings settings;
        settings.exr_half = false;
        settings.exr_compression = method;
        const std::string file = path(std::string("compressed_") + method + ".exr");
        write_image(film, file, settings);
        const std::string name = std::string(method).substr(0, std::string(method).find(':'));
        EXPECT_EQ(read_spec(file).get_string_attribute("compression"), name) << method;
        const Film back = read_film(file);
        ASSERT_EQ(back.beauty.size(), film.beauty.size()) << method;
        for (size_t i = 0; i < film.beauty.size(); ++i) {
            EXPECT_EQ(back.beauty[i], film.beauty[i]) << method << " pixel " << i;
            EXPECT_EQ(back.prim_id[i], film.prim_id[i]) << method << " pixel " << i;
        }
    }
    for (const char* bad : {"zip:0", "zip:10", "zip:", "piz:3", "dwaa", "b44", "ZIP", ""}) {
        OutputSettings settings;
        settings.exr_compression = bad;
        const std::string file = path("bad_compression.exr");
        try {
            write_image(film, file, settings);
            ADD_FAILURE() << "'" << bad << "' accepted";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("bad_compression.exr: "), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find("EXR compression"), std::string::npos) << e.what();
        }
        EXPECT_FALSE(fs::exists(file)) << bad;
    }
}

TEST_F(ImageOutputTest, ExrFloatRoundTripsExactlyWithAovsWindowAndMetadata) {
    const Film film = make_aov_film();
    OutputSettings settings;
    settings.exr_half = false;
    settings.metadata = {{"whitted:commandLine", "whitted render scene.gltf -o out.exr"},
                         {"whitted:version", "0.1.0"},
                         {"whitted:stats", "rays=123"}};
    const std::string file = path("aov.exr");
    write_image(film, file, settings);

    const OIIO::ImageSpec spec = read_spec(file);
    // Data window = crop, display window = full image.
    EXPECT_EQ(spec.x, 2);
    EXPECT_EQ(spec.y, 1);
    EXPECT_EQ(spec.width, 4);
    EXPECT_EQ(spec.height, 3);
    EXPECT_EQ(spec.full_x, 0);
    EXPECT_EQ(spec.full_y, 0);
    EXPECT_EQ(spec.full_width, 7);
    EXPECT_EQ(spec.full_height, 5);
    EXPECT_EQ(spec.nchannels, 3 + 1 + 3 + 3 + 1 + 1);
    EXPECT_EQ(spec.get_string_attribute("compression"), "zip");
    for (const auto& [key, value] : settings.metadata) EXPECT_EQ(spec.get_string_attribute(key), value) << key;

    // Channels by name (OpenEXR stores them sorted; OIIO puts R, G, B first).
    struct Expect { const char* name; OIIO::TypeDesc type; };
    for (Expect e : {Expect{"R", OIIO::TypeFloat}, Expect{"G", OIIO::TypeFloat}, Expect{"B", OIIO::TypeFloat},
                     Expect{"Z", OIIO::TypeFloat}, Expect{"N.X", OIIO::TypeFloat}, Expect{"N.Y", OIIO::TypeFloat},
                     Expect{"N.Z", OIIO::TypeFloat}, Expect{"albedo.R", OIIO::TypeFloat},
                     Expect{"albedo.G", OIIO::TypeFloat}, Expect{"albedo.B", OIIO::TypeFloat},
                     Expect{"primId", OIIO::TypeUInt}, Expect{"instId", OIIO::TypeUInt}}) {
        int c = channel_index(spec, e.name);
        ASSERT_GE(c, 0) << e.name;
        EXPECT_EQ(spec.channelformat(c), e.type) << e.name;
    }
    EXPECT_EQ(channel_index(spec, "R"), 0);
    EXPECT_EQ(channel_index(spec, "G"), 1);
    EXPECT_EQ(channel_index(spec, "B"), 2);

    auto read_float = [&](const char* name) {
        int c = channel_index(spec, name);
        return read_channels<float>(file, c, c + 1, OIIO::TypeFloat);
    };
    auto read_uint = [&](const char* name) {
        int c = channel_index(spec, name);
        return read_channels<uint32_t>(file, c, c + 1, OIIO::TypeUInt);
    };
    const auto rgb = read_channels<float>(file, 0, 3, OIIO::TypeFloat);
    const auto z = read_float("Z");
    const auto nx = read_float("N.X"), ny = read_float("N.Y"), nz = read_float("N.Z");
    const auto ar = read_float("albedo.R"), ag = read_float("albedo.G"), ab = read_float("albedo.B");
    const auto prim = read_uint("primId"), inst = read_uint("instId");
    for (size_t i = 0; i < film.beauty.size(); ++i) {
        EXPECT_EQ(rgb[3 * i + 0], film.beauty[i].x) << i;
        EXPECT_EQ(rgb[3 * i + 1], film.beauty[i].y) << i;
        EXPECT_EQ(rgb[3 * i + 2], film.beauty[i].z) << i;
        EXPECT_EQ(z[i], film.depth[i]) << i;
        EXPECT_EQ(nx[i], film.normal[i].x) << i;
        EXPECT_EQ(ny[i], film.normal[i].y) << i;
        EXPECT_EQ(nz[i], film.normal[i].z) << i;
        EXPECT_EQ(ar[i], film.albedo[i].x) << i;
        EXPECT_EQ(ag[i], film.albedo[i].y) << i;
        EXPECT_EQ(ab[i], film.albedo[i].z) << i;
        EXPECT_EQ(prim[i], film.prim_id[i]) << i;
        EXPECT_EQ(inst[i], film.inst_id[i]) << i;
    }

    // read_image_rgb returns the stored beauty of the data window.
    int w = 0, h = 0;
    const std::vector<float> back = read_image_rgb(file, w, h);
    EXPECT_EQ(w, 4);
    EXPECT_EQ(h, 3);
    EXPECT_EQ(back, rgb);
}

TEST_F(ImageOutputTest, ExrHalfIsWithinHalfPrecision) {
    Film film = make_film(16, 8);
    for (size_t i = 0; i < film.beauty.size(); ++i)
        film.beauty[i] = Color(float(i) / 37.f, 0.18f, 1000.f + float(i));
    const std::string file = path("beauty.exr");
    write_image(film, file, OutputSettings{});  // exr_half defaults to true

    const OIIO::ImageSpec spec = read_spec(file);
    EXPECT_EQ(spec.nchannels, 3);
    EXPECT_EQ(spec.format, OIIO::TypeHalf);
    int w = 0, h = 0;
    const std::vector<float> back = read_image_rgb(file, w, h);
    ASSERT_EQ(back.size(), film.beauty.size() * 3);
    for (size_t i = 0; i < film.beauty.size(); ++i)
        for (int c = 0; c < 3; ++c) {
            float v = film.beauty[i][c];
            // Half has an 11-bit significand: relative error <= 2^-11 after rounding.
            EXPECT_NEAR(back[3 * i + size_t(c)], v, std::abs(v) * 0x1p-11f + 1e-7f) << i << "," << c;
        }
}

// ---- display-referred files ------------------------------------------------------------------

namespace {

/// One row of linear greys and special values, with their expected Standard-view codes.
struct Probe {
    float linear;
    double expected_linear;  ///< what the value should behave like (NaN -> 0, +inf -> large)
};
const std::vector<Probe> kProbes = {
    {0.f, 0.0},   {0.001f, 0.001}, {0.01f, 0.01},   {0.05f, 0.05}, {0.18f, 0.18}, {0.5f, 0.5},
    {0.75f, 0.75}, {1.f, 1.0},      {4.f, 4.0},      {-0.5f, -0.5}, {kNaN, 0.0},  {kInf, 1e30},
    {-kInf, -1e30},
};

Film make_probe_film() {
    Film film = make_film(int(kProbes.size()), 1);
    for (size_t i = 0; i < kProbes.size(); ++i) film.beauty[i] = Color(kProbes[i].linear);
    return film;
}

}  // namespace

TEST_F(ImageOutputTest, Png8BitCodesMatchTheSrgbCurve) {
    const std::string file = path("probe.png");
    write_image(make_probe_film(), file, OutputSettings{});

    OIIO::ImageSpec spec;
    const auto codes = read_channels<uint8_t>(file, 0, 3, OIIO::TypeUInt8, &spec);
    EXPECT_EQ(spec.format, OIIO::TypeUInt8);
    ASSERT_EQ(codes.size(), kProbes.size() * 3);
    for (size_t i = 0; i < kProbes.size(); ++i)
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(int(codes[3 * i + size_t(c)]), expected_code(kProbes[i].expected_linear, 255), 1)
                << "linear " << kProbes[i].linear;
    // The documented anchors, exactly.
    EXPECT_EQ(codes[3 * 4], 118);  // 0.18 -> 0.4614 * 255
    EXPECT_EQ(codes[3 * 10], 0);   // NaN -> 0
    EXPECT_EQ(codes[3 * 11], 255); // +inf -> 255
    EXPECT_EQ(codes[3 * 12], 0);   // -inf -> 0
}

TEST_F(ImageOutputTest, Png16BitCodesMatchTheSrgbCurve) {
    OutputSettings settings;
    settings.bits = 16;
    const std::string file = path("probe16.png");
    write_image(make_probe_film(), file, settings);

    OIIO::ImageSpec spec;
    const auto codes = read_channels<uint16_t>(file, 0, 3, OIIO::TypeUInt16, &spec);
    EXPECT_EQ(spec.format, OIIO::TypeUInt16);
    for (size_t i = 0; i < kProbes.size(); ++i)
        EXPECT_NEAR(int(codes[3 * i]), expected_code(kProbes[i].expected_linear, 65535), 1)
            << "linear " << kProbes[i].linear;
    EXPECT_EQ(codes[3 * 10], 0);
    EXPECT_EQ(codes[3 * 11], 65535);
}

TEST_F(ImageOutputTest, NanAndInfAreSafeThroughAces) {
    OutputSettings settings;
    settings.color.view = "ACES 1.0 SDR-video";
    Film film = make_film(3, 1);
    film.beauty = {Color(kNaN), Color(kInf), Color(kNaN, 0.18f, kInf)};
    const std::string file = path("aces.png");
    write_image(film, file, settings);
    const auto codes = read_channels<uint8_t>(file, 0, 3, OIIO::TypeUInt8);
    EXPECT_EQ(codes[0], 0);
    EXPECT_EQ(codes[1], 0);
    EXPECT_EQ(codes[2], 0);
    // Infinity tone-maps to display white (or within a code of it).
    EXPECT_GE(codes[3], 254);
    EXPECT_GE(codes[4], 254);
    EXPECT_GE(codes[5], 254);
}

TEST_F(ImageOutputTest, TiffDefaultsTo16BitAndJpegWrites) {
    Film film = make_film(8, 4);
    for (size_t i = 0; i < film.beauty.size(); ++i) film.beauty[i] = Color(0.18f);

    const std::string tif = path("grey.TIF");  // extensions are case-insensitive
    write_image(film, tif, OutputSettings{});
    OIIO::ImageSpec spec;
    const auto codes = read_channels<uint16_t>(tif, 0, 3, OIIO::TypeUInt16, &spec);
    EXPECT_EQ(spec.format, OIIO::TypeUInt16);
    EXPECT_NEAR(int(codes[0]), expected_code(0.18, 65535), 1);

    const std::string jpg = path("grey.jpeg");
    write_image(film, jpg, OutputSettings{});
    const auto jcodes = read_channels<uint8_t>(jpg, 0, 3, OIIO::TypeUInt8);
    EXPECT_NEAR(int(jcodes[0]), 118, 2);  // lossy, but a flat field survives
}

TEST_F(ImageOutputTest, DisplayFilesHoldOnlyTheCrop) {
    Film film(10, 8, PixelWindow{3, 2, 7, 5}, AovSet{});
    for (size_t i = 0; i < film.beauty.size(); ++i) film.beauty[i] = Color(float(i) / float(film.beauty.size()));
    const std::string file = path("crop.png");
    write_image(film, file, OutputSettings{});
    const OIIO::ImageSpec spec = read_spec(file);
    EXPECT_EQ(spec.width, 4);
    EXPECT_EQ(spec.height, 3);
    int w = 0, h = 0;
    const auto rgb = read_image_rgb(file, w, h);
    // The last pixel is the brightest: row-major order of the window is kept.
    EXPECT_NEAR(rgb.back(), float(expected_code(11.0 / 12.0, 255)) / 255.f, 1.5f / 255.f);
}

TEST_F(ImageOutputTest, BadBitDepthsAreErrors) {
    Film film = make_film(2, 2);
    OutputSettings settings;
    settings.bits = 12;
    EXPECT_NE(error_of([&] { write_image(film, path("a.png"), settings); }).find("bit depth 12"), std::string::npos);
    settings.bits = 16;
    EXPECT_NE(error_of([&] { write_image(film, path("a.jpg"), settings); }).find("JPEG"), std::string::npos);
    EXPECT_TRUE(listing().empty());
}

// ---- atomic writes and failures ------------------------------------------------------------------

TEST_F(ImageOutputTest, SuccessfulWriteLeavesNoTemporaryFile) {
    Film film = make_film(4, 4);
    write_image(film, path("a.png"), OutputSettings{});
    write_image(film, path("b.exr"), OutputSettings{});
    write_image(film, path("a.png"), OutputSettings{});  // replacing an existing file
    EXPECT_EQ(listing(), (std::vector<std::string>{"a.png", "b.exr"}));
}

TEST_F(ImageOutputTest, MissingDirectoryThrowsAndCreatesNothing) {
    const std::string file = path("no/such/dir/out.png");
    std::string msg = error_of([&] { write_image(make_film(2, 2), file, OutputSettings{}); });
    EXPECT_NE(msg.find(file), std::string::npos) << msg;
    EXPECT_FALSE(fs::exists(m_dir / "no"));
    EXPECT_TRUE(listing().empty());
}

TEST_F(ImageOutputTest, UnknownExtensionThrowsNamingFileAndSupportedExtensions) {
    const std::string file = path("out.bmp");
    std::string msg = error_of([&] { write_image(make_film(2, 2), file, OutputSettings{}); });
    EXPECT_NE(msg.find(file), std::string::npos) << msg;
    EXPECT_NE(msg.find(".exr, .png, .jpg, .jpeg, .tif, .tiff"), std::string::npos) << msg;
    msg = error_of([&] { write_image(make_film(2, 2), path("noextension"), OutputSettings{}); });
    EXPECT_NE(msg.find("noextension"), std::string::npos) << msg;
    EXPECT_TRUE(listing().empty());
}

TEST_F(ImageOutputTest, FailedRenameRemovesTheTemporaryFile) {
    // The destination is a non-empty directory: encoding succeeds, the rename cannot.
    fs::create_directories(m_dir / "taken.png" / "inside");
    std::string msg = error_of([&] { write_image(make_film(2, 2), path("taken.png"), OutputSettings{}); });
    EXPECT_NE(msg.find(path("taken.png")), std::string::npos) << msg;
    EXPECT_EQ(listing(), std::vector<std::string>{"taken.png"});
}

TEST_F(ImageOutputTest, InconsistentFilmIsAnError) {
    Film film = make_film(4, 4);
    film.beauty.pop_back();
    EXPECT_NE(error_of([&] { write_image(film, path("x.exr"), OutputSettings{}); }).find("beauty"),
              std::string::npos);
    Film outside(4, 4, PixelWindow{2, 2, 6, 6}, AovSet{});
    EXPECT_NE(error_of([&] { write_image(outside, path("x.png"), OutputSettings{}); }).find("outside"),
              std::string::npos);
    EXPECT_TRUE(listing().empty());
}

TEST_F(ImageOutputTest, ReadingAMissingFileIsAnError) {
    int w = 0, h = 0;
    const std::string file = path("missing.exr");
    std::string msg = error_of([&] { read_image_rgb(file, w, h); });
    EXPECT_NE(msg.find(file), std::string::npos) << msg;
}
