// Image files and the tone map.
#include <bit>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>

#include "skybake/error.h"
#include "skybake/image.h"
#include "skybake/image_io.h"

// stb_image, the reference decoder for JPEG here (skybake reads JPEG with libjpeg-turbo).
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_STATIC
#define STBI_ONLY_JPEG
#include <stb/stb_image.h>

using namespace skybake;
namespace fs = std::filesystem;

namespace {
fs::path temp(const std::string& name) {
    const fs::path dir = fs::temp_directory_path() / ("skybake-image-test-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    return dir / name;
}
Image gradient(int w, int h) {
    Image img(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float* p = img.pixel(x, y);
            p[0] = float(x) / float(w - 1) * 4.0f; // HDR
            p[1] = float(y) / float(h - 1);
            p[2] = 1e-4f * float(x + y);
        }
    return img;
}
} // namespace

TEST(ImageFiles, ExrKeepsFloatsExactly) {
    const Image a = gradient(37, 21);
    save_image(temp("a.exr"), a);
    const Image b = load_image(temp("a.exr"));
    ASSERT_EQ(b.width, a.width);
    ASSERT_EQ(b.height, a.height);
    for (std::size_t i = 0; i < a.rgb.size(); ++i)
        ASSERT_EQ(std::bit_cast<std::uint32_t>(a.rgb[i]), std::bit_cast<std::uint32_t>(b.rgb[i])) << i;
}

TEST(ImageFiles, PngRoundTripsWithinOneCode) {
    Image a(16, 4);
    for (std::size_t i = 0; i < a.rgb.size(); ++i)
        a.rgb[i] = float(i % 17) / 16.0f; // in [0, 1]
    save_png(temp("a.png"), a, {0.0f, ToneCurve::Clamp});
    const Image b = load_image(temp("a.png"));
    for (std::size_t i = 0; i < a.rgb.size(); ++i) {
        // One 8-bit sRGB code is at most ~1/255 in encoded space.
        EXPECT_NEAR(linear_to_srgb(b.rgb[i]), linear_to_srgb(a.rgb[i]), 0.5f / 255.0f + 1e-5f);
    }
}

TEST(ImageFiles, BadPathsAndExtensions) {
    const Image a = gradient(4, 4);
    EXPECT_THROW(save_image(temp("a.bmp"), a), Error);
    EXPECT_THROW(save_image(temp("missing_dir/a.png"), a), Error);
    EXPECT_THROW(save_image(temp("empty.png"), Image()), Error);
    EXPECT_THROW(load_image(temp("nope.exr")), Error);
    const fs::path junk = temp("junk.png");
    { std::ofstream(junk) << "not a png"; }
    EXPECT_THROW(load_image(junk), Error);
}

// A few header bytes must not make the loader allocate what they claim: a
// Radiance header of 16000 x 16000 pixels and no pixel data (stb_image would
// allocate 3 GiB and fill it with zeros) is refused before any allocation.
TEST(ImageFiles, AHugeHeaderIsAnErrorNotAnAllocation) {
    const std::string hdr = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 16000 +X 16000\n";
    try {
        load_image_from_memory(hdr.data(), hdr.size(), "hdr", "huge.hdr");
        FAIL() << "a 256-Mpixel header was accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("larger than the limit"), std::string::npos) << e.what();
    }
    const std::string truncated = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 4096 +X 8192\n";
    try {
        load_image_from_memory(truncated.data(), truncated.size(), "hdr", "truncated.hdr");
        FAIL() << "a header without pixels was read as a black map";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("truncated"), std::string::npos) << e.what();
    }
    const Image small = gradient(8, 4);
    save_image(temp("small.exr"), small);
    std::ifstream in(temp("small.exr"), std::ios::binary);
    const std::string exr((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(load_image_from_memory(exr.data(), exr.size(), ".EXR", "small.exr").width, 8);
    EXPECT_THROW(load_image_from_memory(exr.data(), exr.size(), "exr", "small.exr", 31), Error);
}

// JPEGs are decoded by libjpeg-turbo; Debian's stb_image 2.27 (the PNG and
// HDR reader) is the independent decoder to compare with on a valid file.
TEST(ImageFiles, JpegDecodesAsAnIndependentDecoderDoes) {
    const fs::path path = "/usr/share/assimp/models/LWO/LWO2/MappingModes/earthSpherical.jpg";
    if (!fs::exists(path))
        GTEST_SKIP() << "assimp-testmodels is not installed";
    std::ifstream in(path, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const Image img = load_image(path);
    int w = 0, h = 0, comp = 0;
    unsigned char* ref = stbi_load_from_memory(reinterpret_cast<const unsigned char*>(bytes.data()), int(bytes.size()),
                                               &w, &h, &comp, 3);
    ASSERT_NE(ref, nullptr) << stbi_failure_reason();
    ASSERT_EQ(img.width, w);
    ASSERT_EQ(img.height, h);
    double sum = 0.0;
    for (std::size_t i = 0; i < img.rgb.size(); ++i)
        sum += std::abs(double(linear_to_srgb(img.rgb[i])) * 255.0 - double(ref[i]));
    stbi_image_free(ref);
    // The two differ only in IDCT and chroma upsampling rounding.
    EXPECT_LT(sum / double(img.rgb.size()), 1.5) << "mean |difference| in 8-bit sRGB levels";
    EXPECT_THROW(load_image_from_memory(bytes.data(), bytes.size() / 2, "jpg", "half.jpg"), Error); // truncated
    EXPECT_THROW(load_image_from_memory(bytes.data(), bytes.size(), "jpg", "big.jpg", std::uint64_t(w) * h - 1), Error);
}

// Corrupt JPEGs are errors: a Huffman table of more than 256 codes and a scan
// whose tables no DHT defined (stb_image 2.27 wrote past its tables and read
// uninitialised ones), and a scan that runs out of bits where stb_image
// shifted by 32 (found by the image fuzzer).
TEST(ImageFiles, CorruptJpegsAreErrors) {
    const auto expect_corrupt = [](const std::string& jpeg, const char* what) {
        try {
            load_image_from_memory(jpeg.data(), jpeg.size(), "jpg", "bad.jpg");
            ADD_FAILURE() << what << " was accepted";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("corrupt JPEG"), std::string::npos) << e.what();
            EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
        }
    };
    std::string jpeg = "\xFF\xD8\xFF\xC4";
    jpeg += std::string("\x00\x13\x00", 3); // length 19: one table, class 0, id 0
    jpeg += std::string(16, '\x20');        // 16 counts of 32: 512 codes
    jpeg += std::string(512, '\x01') + "\xFF\xD9";
    expect_corrupt(jpeg, "a Huffman table of 512 codes");
    std::string scan = "\xFF\xD8\xFF\xDA";
    scan += std::string("\x00\x08\x01\x01\x00\x00\x3F\x00", 8); // one component, tables 0/0, Ss 0, Se 63
    scan += std::string(64, '\x55') + "\xFF\xD9";
    expect_corrupt(scan, "a scan without Huffman tables");
    std::ifstream in(fs::path(SKYBAKE_SOURCE_DIR) / "tests/data/fuzz/jpeg_scan_out_of_bits.jpg", std::ios::binary);
    const std::string out_of_bits((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    ASSERT_GT(out_of_bits.size(), 900u);
    expect_corrupt(out_of_bits, "a progressive scan that runs out of bits");
}

TEST(ToneMap, SrgbTransferInverts) {
    for (float v = 0.0f; v <= 1.0f; v += 1.0f / 64.0f)
        EXPECT_NEAR(srgb_to_linear(linear_to_srgb(v)), v, 1e-6f);
    EXPECT_NEAR(linear_to_srgb(0.0031308f), 0.04045f, 1e-5f); // the two branches meet
    // IEC 61966-2-1, each branch pinned: 1.055 v^(1/2.4) − 0.055 and 12.92 v.
    EXPECT_NEAR(linear_to_srgb(0.5f), 0.735357f, 2e-6f);
    EXPECT_NEAR(linear_to_srgb(0.18f), 0.461356f, 2e-6f);
    EXPECT_NEAR(linear_to_srgb(0.001f), 0.01292f, 1e-7f);
    EXPECT_NEAR(srgb_to_linear(0.5f), 0.214041f, 2e-6f);
    EXPECT_NEAR(srgb_to_linear(0.02f), 0.02f / 12.92f, 1e-8f);
    EXPECT_NEAR(linear_to_srgb(2.0f), 1.0f, 1e-6f); // clamped to 1 first (1.055 − 0.055 in float)
}

TEST(ToneMap, AcesCurveAtKnownPoints) {
    // Narkowicz 2015: x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14).
    EXPECT_NEAR(tone_map_value(1.0f, {0.0f, ToneCurve::Aces}), 2.54f / 3.16f, 1e-6f); // 0.803797
    EXPECT_NEAR(tone_map_value(0.18f, {0.0f, ToneCurve::Aces}), 0.266899f, 2e-6f);  // middle grey
    EXPECT_NEAR(tone_map_value(0.5f, {0.0f, ToneCurve::Aces}), 0.616307f, 2e-6f);
    EXPECT_NEAR(tone_map_value(0.25f, {1.0f, ToneCurve::Aces}), 0.616307f, 2e-6f); // +1 EV before the curve
    EXPECT_NEAR(tone_map_value(4.0f, {0.0f, ToneCurve::Aces}), 0.973417f, 2e-6f);
    EXPECT_EQ(tone_map_value(20.0f, {0.0f, ToneCurve::Aces}), 1.0f); // 1.0210, clamped
    EXPECT_NEAR(tone_map_value(1e-3f, {0.0f, ToneCurve::Aces}), 2.312358e-4f, 1e-9f);
}

TEST(ToneMap, CurvesAreMonotonicAndBounded) {
    for (ToneCurve c : {ToneCurve::Clamp, ToneCurve::Reinhard, ToneCurve::Aces}) {
        float prev = -1.0f;
        for (float x = 0.0f; x < 100.0f; x = x * 1.1f + 1e-3f) {
            const float y = tone_map_value(x, {0.0f, c});
            EXPECT_GE(y, prev);
            EXPECT_LE(y, 1.0f);
            prev = y;
        }
    }
    EXPECT_FLOAT_EQ(tone_map_value(0.5f, {1.0f, ToneCurve::Clamp}), 1.0f); // +1 EV doubles
    EXPECT_FLOAT_EQ(tone_map_value(1.0f, {0.0f, ToneCurve::Reinhard}), 0.5f);
    EXPECT_EQ(tone_map_value(std::nanf(""), {}), 0.0f);
    EXPECT_EQ(tone_map_value(-1.0f, {}), 0.0f);
    EXPECT_THROW(parse_tone_curve("filmic"), Error);
}
