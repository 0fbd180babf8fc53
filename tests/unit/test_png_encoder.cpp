// The in-house PNG encoder (src/output/png_encoder.h): files decode, through an independent
// reader (OpenImageIO's libpng, which checks every CRC and the Adler-32), to exactly the codes
// given, at 8 and 16 bits, for sizes that leave partial bands and one-row bands; the bytes do not
// depend on the thread count; metadata comes back as text; write_image's PNG holds exactly
// display_codes' values, and so do TIFF files (written through libtiff, strips deflated in
// parallel); JPEG files are the ones OpenImageIO writes at its default quality. And the image
// module: no file written loads OIIO; reading a non-EXR image does.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <unistd.h>

#include <OpenImageIO/imageio.h>
#include <tbb/global_control.h>

#include "core/error.h"
#include "core/image_files.h"
#include "core/image_files_display.h"
#include "output/image_output.h"
#include "output/png_encoder.h"

namespace fs = std::filesystem;
using namespace whitted;

namespace {

fs::path temp_file(const std::string& name) {
    return fs::temp_directory_path() / fmt::format("whitted_png_{}_{}", ::getpid(), name);
}

void save(const fs::path& path, const std::vector<uint8_t>& bytes) {
    std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

/// A smooth gradient with noise and flat runs: every filter type wins somewhere.
std::vector<uint8_t> test_codes(int w, int h, int bits, uint32_t seed) {
    std::mt19937 rng(seed);
    const size_t bytes = bits == 16 ? 2 : 1;
    std::vector<uint8_t> out(size_t(w) * size_t(h) * 3 * bytes);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) {
                const size_t i = (size_t(y) * size_t(w) + size_t(x)) * 3 + size_t(c);
                const uint32_t noise = (x / 7 + y / 5) % 3 == 0 ? rng() % 64 : 0;
                const uint32_t v = uint32_t(x * 3 + y * 2 + c * 50) + noise;
                if (bits == 8) {
                    out[i] = uint8_t(v);
                } else {
                    const uint16_t s = uint16_t(v * 257u + rng() % 3);
                    std::memcpy(&out[2 * i], &s, 2);
                }
            }
    return out;
}

/// A w x h film of random values across the display range and beyond it.
Film random_film(int w, int h, uint32_t seed) {
    Film film(w, h, PixelWindow{0, 0, w, h}, AovSet{});
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-0.1f, 1.6f);
    for (Color& c : film.beauty) c = Color(u(rng), u(rng), u(rng));
    return film;
}

struct Decoded {
    OIIO::ImageSpec spec;
    std::vector<uint8_t> codes;  ///< native layout, as encode_png takes them
};

Decoded decode(const fs::path& path, int bits) {
    auto in = OIIO::ImageInput::open(path.string());
    if (!in) throw std::runtime_error(OIIO::geterror());
    Decoded d;
    d.spec = in->spec();
    d.codes.resize(size_t(d.spec.width) * size_t(d.spec.height) * 3 * (bits == 16 ? 2 : 1));
    if (!in->read_image(0, 0, 0, 3, bits == 16 ? OIIO::TypeUInt16 : OIIO::TypeUInt8, d.codes.data()))
        throw std::runtime_error(in->geterror());
    return d;
}

}  // namespace

TEST(PngEncoder, DecodesToTheSameCodesAt8And16Bits) {
    struct Case {
        int w, h, bits, band_rows, level;
    };
    for (const Case& c : {Case{1, 1, 8, 0, 2}, Case{37, 23, 8, 1, 2}, Case{37, 23, 8, 5, 6}, Case{64, 64, 16, 0, 2},
                          Case{33, 17, 16, 3, 1}, Case{300, 211, 8, 0, 0}, Case{300, 211, 8, 0, 9},
                          Case{1920, 40, 8, 7, 2}}) {
        SCOPED_TRACE(fmt::format("{}x{} {} bits, band rows {}, level {}", c.w, c.h, c.bits, c.band_rows, c.level));
        const std::vector<uint8_t> codes = test_codes(c.w, c.h, c.bits, uint32_t(c.w * 131 + c.h));
        const std::vector<uint8_t> png = encode_png(codes, c.w, c.h, c.bits, {}, PngOptions{c.level, c.band_rows});
        const fs::path file = temp_file("codes.png");
        save(file, png);
        const Decoded d = decode(file, c.bits);
        EXPECT_EQ(d.spec.width, c.w);
        EXPECT_EQ(d.spec.height, c.h);
        EXPECT_EQ(d.spec.nchannels, 3);
        EXPECT_EQ(d.spec.format, c.bits == 16 ? OIIO::TypeUInt16 : OIIO::TypeUInt8);
        EXPECT_TRUE(d.codes == codes) << "decoded codes differ";
        fs::remove(file);
    }
}

TEST(PngEncoder, BytesDoNotDependOnTheThreadCount) {
    const std::vector<uint8_t> codes = test_codes(640, 360, 8, 7);
    std::vector<uint8_t> one, many;
    {
        tbb::global_control serial(tbb::global_control::max_allowed_parallelism, 1);
        one = encode_png(codes, 640, 360, 8, {{"k", "v"}});
    }
    many = encode_png(codes, 640, 360, 8, {{"k", "v"}});
    EXPECT_TRUE(one == many);
    // And many bands (primed with the previous band's bytes) cost little over one stream.
    const size_t one_band = encode_png(codes, 640, 360, 8, {}, PngOptions{2, 360}).size();
    const size_t bands = encode_png(codes, 640, 360, 8, {}, PngOptions{2, 8}).size();
    EXPECT_LT(double(bands), 1.05 * double(one_band)) << one_band << " vs " << bands;
}

TEST(PngEncoder, TextComesBackAsMetadata) {
    const std::vector<uint8_t> codes = test_codes(8, 8, 8, 1);
    const std::string long_key(100, 'k');
    const std::vector<uint8_t> png = encode_png(
        codes, 8, 8, 8, {{"Software", "whitted"}, {"whitted:stats", "a | b"}, {"unicode", "caf\xc3\xa9"}, {long_key, "cut"}});
    const fs::path file = temp_file("text.png");
    save(file, png);
    const Decoded d = decode(file, 8);
    EXPECT_EQ(d.spec.get_string_attribute("Software"), "whitted");
    EXPECT_EQ(d.spec.get_string_attribute("whitted:stats"), "a | b");
    EXPECT_EQ(d.spec.get_string_attribute("unicode"), "caf\xc3\xa9");
    EXPECT_EQ(d.spec.get_string_attribute(long_key.substr(0, 79)), "cut");
    fs::remove(file);
}

TEST(PngEncoder, RejectsBadArguments) {
    const std::vector<uint8_t> codes(12, 0);
    EXPECT_THROW(encode_png(codes, 2, 2, 12, {}), Error);
    EXPECT_THROW(encode_png(codes, 3, 2, 8, {}), Error);  // 18 bytes needed
    EXPECT_THROW(encode_png(codes, 0, 2, 8, {}), Error);
    EXPECT_THROW(encode_png(codes, 2, 2, 8, {}, PngOptions{10, 0}), Error);
}

TEST(PngEncoder, WriteImageStoresExactlyTheDisplayCodes) {
    // A film with values across the range (and beyond it): the PNG holds display_codes' bytes.
    const int w = 97, h = 61;
    const Film film = random_film(w, h, 3);
    for (int bits : {8, 16}) {
        OutputSettings settings;
        settings.bits = bits;
        settings.metadata["whitted:test"] = "yes";
        const fs::path file = temp_file(fmt::format("film{}.png", bits));
        write_image(film, file.string(), settings);
        std::vector<uint8_t> expected(size_t(w) * size_t(h) * 3 * (bits == 16 ? 2 : 1));
        display_codes(film.beauty, DisplayTransform(settings.color), bits, expected);
        const Decoded d = decode(file, bits);
        EXPECT_TRUE(d.codes == expected) << bits << " bits";
        EXPECT_EQ(d.spec.get_string_attribute("whitted:test"), "yes");
        EXPECT_EQ(d.spec.get_string_attribute("whitted:view"), "Standard");
        fs::remove(file);
    }
}

TEST(TiffWriter, StoresExactlyTheDisplayCodesForAnySize) {
    // Heights that leave a partial strip (strips of 32 rows), one-pixel-wide images, 8 and 16 bits,
    // Deflate (the default, and level 9) and uncompressed strips (--tiff-compression).
    for (auto [w, h] : {std::pair{97, 61}, std::pair{1, 33}, std::pair{40, 32}, std::pair{3, 1}}) {
        const Film film = random_film(w, h, uint32_t(w * 1000 + h));
        for (int bits : {8, 16})
            for (const char* compression : {"zip", "zip:9", "none"}) {
                OutputSettings settings;
                settings.bits = bits;
                settings.tiff_compression = compression;
                settings.metadata["whitted:test"] = "yes";
                const fs::path file = temp_file(fmt::format("film{}x{}_{}.tif", w, h, bits));
                write_image(film, file.string(), settings);
                std::vector<uint8_t> expected(size_t(w) * size_t(h) * 3 * (bits == 16 ? 2 : 1));
                display_codes(film.beauty, DisplayTransform(settings.color), bits, expected);
                const Decoded d = decode(file, bits);
                const std::string what = fmt::format("{}x{} at {} bits, {}", w, h, bits, compression);
                EXPECT_EQ(d.spec.format, bits == 16 ? OIIO::TypeUInt16 : OIIO::TypeUInt8) << what;
                EXPECT_TRUE(d.codes == expected) << what;
                EXPECT_EQ(d.spec.get_string_attribute("compression"), compression == std::string("none") ? "none" : "zip")
                    << what;
                EXPECT_EQ(d.spec.get_string_attribute("Software"), "whitted " WHITTED_VERSION);
                EXPECT_NE(d.spec.get_string_attribute("ImageDescription").find("whitted:test: yes"), std::string::npos);
                fs::remove(file);
            }
    }
}

// --tiff-compression: a name the flag does not take is one error naming the file, and writes
// nothing (it used to be that any compression attribute but zip:N meant level 1).
TEST(TiffWriter, UnknownCompressionIsAnErrorAndWritesNothing) {
    const Film film = random_film(8, 8, 3);
    for (const char* bad : {"zip:0", "zip:13", "zip:", "zip:x", "lzw", "deflate", "ZIP", ""}) {
        OutputSettings settings;
        settings.tiff_compression = bad;
        const fs::path file = temp_file("bad_compression.tif");
        fs::remove(file);
        try {
            write_image(film, file.string(), settings);
            ADD_FAILURE() << "'" << bad << "' accepted";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("bad_compression.tif: "), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find("TIFF compression"), std::string::npos) << e.what();
        }
        EXPECT_FALSE(fs::exists(file)) << bad;
    }
    EXPECT_EQ(tiff_compression_error("none"), "");
    EXPECT_EQ(tiff_compression_error("zip:12"), "");
}

TEST(TiffWriter, BytesDoNotDependOnTheThreadCount) {
    Film film(300, 200, PixelWindow{0, 0, 300, 200}, AovSet{});
    for (size_t i = 0; i < film.beauty.size(); ++i) film.beauty[i] = Color(float(i % 300) / 300.f, float(i / 300) / 200.f, 0.5f);
    std::vector<std::string> files;
    for (int threads : {1, 2, 5}) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
        const fs::path file = temp_file(fmt::format("threads{}.tif", threads));
        write_image(film, file.string(), OutputSettings{});
        std::ifstream in(file, std::ios::binary);
        files.emplace_back(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
        fs::remove(file);
    }
    EXPECT_EQ(files[0], files[1]);
    EXPECT_EQ(files[0], files[2]);
}

TEST(JpegWriter, DecodesLikeOpenImageIOsOwnJpegOfTheSameCodes) {
    // whitted's JPEG against OIIO's JPEG (its default quality) of the very same 8-bit codes.
    const int w = 120, h = 77;
    Film film(w, h, PixelWindow{0, 0, w, h}, AovSet{});
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) film.beauty[size_t(y * w + x)] = Color(float(x) / w, float(y) / h, float((x * y) % 17) / 17.f);
    const fs::path ours = temp_file("ours.jpg"), theirs = temp_file("theirs.jpg");
    write_image(film, ours.string(), OutputSettings{});
    std::vector<uint8_t> codes(size_t(w) * size_t(h) * 3);
    display_codes(film.beauty, DisplayTransform(ColorSettings{}), 8, codes);
    auto out = OIIO::ImageOutput::create(theirs.string());
    ASSERT_TRUE(out);
    ASSERT_TRUE(out->open(theirs.string(), OIIO::ImageSpec(w, h, 3, OIIO::TypeUInt8)));
    ASSERT_TRUE(out->write_image(OIIO::TypeUInt8, codes.data()));
    out->close();
    const Decoded a = decode(ours, 8), b = decode(theirs, 8);
    EXPECT_TRUE(a.codes == b.codes);
    EXPECT_NE(a.codes, codes) << "a JPEG is lossy: equal codes would mean the test compares nothing";
    fs::remove(ours);
    fs::remove(theirs);
}

// This test program links OIIO itself (for the checks above), so whether whitted's module is
// loaded is asked of whitted, not of the process's library list (tests/cli covers the latter).
TEST(ImageModule, NoWriteLoadsItReadingAPngDoes) {
    Film film(4, 4, PixelWindow{0, 0, 4, 4}, AovSet{});
    film.beauty[5] = Color(0.25f, 0.5f, 2.f);
    const fs::path png = temp_file("lazy.png"), exr = temp_file("lazy.exr"), jpg = temp_file("lazy.jpg"),
                   tif = temp_file("lazy.tif");
    write_image(film, png.string(), OutputSettings{});
    OutputSettings full;
    full.exr_half = false;
    full.metadata["whitted:test"] = "exr";
    write_image(film, exr.string(), full);
    std::map<std::string, std::string> metadata;
    const Film back = read_film(exr.string(), &metadata);
    write_image(film, jpg.string(), OutputSettings{});
    write_image(film, tif.string(), OutputSettings{});
    EXPECT_FALSE(image_module_loaded()) << "writing PNG, EXR, JPEG or TIFF, or reading EXR, went through the OIIO module";
    EXPECT_EQ(back.width(), 4);
    EXPECT_EQ(back.beauty[5].z, 2.f);
    EXPECT_EQ(metadata["Software"], "whitted " WHITTED_VERSION);
    EXPECT_EQ(metadata["whitted:test"], "exr");
    EXPECT_EQ(open_image_file(png.string())->desc().width, 4);
    EXPECT_TRUE(image_module_loaded());
    int w = 0, h = 0;
    EXPECT_EQ(read_image_rgb(jpg.string(), w, h).size(), 4u * 4u * 3u);
    for (const fs::path& f : {png, exr, jpg, tif}) fs::remove(f);
}
