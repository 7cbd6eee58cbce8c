// Image files: PNG through stb_image(_write), EXR through tinyexr.
// Tone curve: K. Narkowicz, "ACES Filmic Tone Mapping Curve", 2015.
#include "skybake/image.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <memory>

#include <fmt/format.h>
#include <tinyexr.h>

#include "skybake/error.h"
#include "skybake/names.h"
#include "skybake/files.h"

#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#include <stb_image_write.h>
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_STATIC
#define STBI_ONLY_PNG
#define STBI_ONLY_JPEG
#define STBI_ONLY_HDR
#include <stb_image.h>

namespace skybake {

namespace fs = std::filesystem;

namespace {

std::string lower_extension(const fs::path& p) {
    std::string ext = p.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

void check_image(const Image& image, const fs::path& path) {
    if (image.width <= 0 || image.height <= 0)
        throw Error("cannot write an empty image", path.string());
    if (image.rgb.size() != std::size_t(image.width) * std::size_t(image.height) * 3)
        throw Error("image buffer size does not match width * height * 3", path.string());
}

} // namespace

namespace {
constexpr NamedValue<ToneCurve> kToneCurveNames[] = {
    {ToneCurve::Clamp, "clamp"}, {ToneCurve::Reinhard, "reinhard"}, {ToneCurve::Aces, "aces"}};
} // namespace

ToneCurve parse_tone_curve(const std::string& name) { return parse_name(kToneCurveNames, name, "tone curve", "curve"); }

float tone_map_value(float linear, const ToneMap& tm) {
    if (!std::isfinite(linear) || linear <= 0.0f)
        return linear > 0.0f ? 1.0f : 0.0f; // +inf -> white, NaN/negative -> black
    const float x = linear * std::exp2(tm.exposure_ev);
    float y = x;
    switch (tm.curve) {
    case ToneCurve::Clamp: y = x; break;
    case ToneCurve::Reinhard: y = x / (1.0f + x); break;
    case ToneCurve::Aces: y = (x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f); break;
    }
    return std::clamp(y, 0.0f, 1.0f);
}

float linear_to_srgb(float v) {
    v = std::clamp(v, 0.0f, 1.0f);
    return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

float srgb_to_linear(float v) {
    v = std::clamp(v, 0.0f, 1.0f);
    return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

double auto_exposure_ev(const Image& img) {
    std::vector<float> lum;
    lum.reserve(img.rgb.size() / 3);
    for (std::size_t i = 0; i + 2 < img.rgb.size(); i += 3) {
        const float l = 0.2126f * img.rgb[i] + 0.7152f * img.rgb[i + 1] + 0.0722f * img.rgb[i + 2];
        if (l > 0.0f && std::isfinite(l))
            lum.push_back(l);
    }
    if (lum.empty())
        return 0.0;
    const std::size_t k = std::min(lum.size() - 1, std::size_t(double(lum.size()) * 0.98));
    std::nth_element(lum.begin(), lum.begin() + std::ptrdiff_t(k), lum.end());
    return -std::log2(double(lum[k]));
}

std::vector<std::uint8_t> to_srgb8(const Image& image, const ToneMap& tm) {
    std::vector<std::uint8_t> out(image.rgb.size());
    for (std::size_t i = 0; i < image.rgb.size(); ++i)
        out[i] = std::uint8_t(std::lround(linear_to_srgb(tone_map_value(image.rgb[i], tm)) * 255.0f));
    return out;
}

void save_png_srgb8(const fs::path& path, int width, int height, const std::uint8_t* rgb) {
    if (width <= 0 || height <= 0)
        throw Error("cannot write an empty image", path.string());
    write_file_atomic(path, [&](const fs::path& tmp) {
        if (!stbi_write_png(tmp.c_str(), width, height, 3, rgb, width * 3))
            throw Error("cannot write PNG", path.string());
    });
}

void save_png(const fs::path& path, const Image& image, const ToneMap& tm) {
    check_image(image, path);
    const auto bytes = to_srgb8(image, tm);
    save_png_srgb8(path, image.width, image.height, bytes.data());
}

void save_exr(const fs::path& path, const Image& image) {
    check_image(image, path);
    // tinyexr's SaveEXR takes interleaved RGB and writes half floats by default;
    // use the full API to keep 32-bit floats.
    const std::size_t n = std::size_t(image.width) * std::size_t(image.height);
    std::vector<float> planes[3];
    for (int c = 0; c < 3; ++c) {
        planes[c].resize(n);
        for (std::size_t i = 0; i < n; ++i)
            planes[c][i] = image.rgb[i * 3 + std::size_t(c)];
    }
    EXRHeader header;
    InitEXRHeader(&header);
    EXRImage exr;
    InitEXRImage(&exr);
    // EXR stores channels in alphabetical order: B, G, R.
    float* ptrs[3] = {planes[2].data(), planes[1].data(), planes[0].data()};
    exr.images = reinterpret_cast<unsigned char**>(ptrs);
    exr.num_channels = 3;
    exr.width = image.width;
    exr.height = image.height;
    EXRChannelInfo channels[3];
    const char* names[3] = {"B", "G", "R"};
    int pixel_types[3] = {TINYEXR_PIXELTYPE_FLOAT, TINYEXR_PIXELTYPE_FLOAT, TINYEXR_PIXELTYPE_FLOAT};
    for (int c = 0; c < 3; ++c) {
        std::snprintf(channels[c].name, sizeof(channels[c].name), "%s", names[c]);
        channels[c].pixel_type = TINYEXR_PIXELTYPE_FLOAT;
        channels[c].p_linear = 0;
    }
    header.num_channels = 3;
    header.channels = channels;
    header.pixel_types = pixel_types;
    header.requested_pixel_types = pixel_types;
    header.compression_type = TINYEXR_COMPRESSIONTYPE_ZIP;
    write_file_atomic(path, [&](const fs::path& tmp) {
        const char* err = nullptr;
        if (SaveEXRImageToFile(&exr, &header, tmp.c_str(), &err) != TINYEXR_SUCCESS) {
            std::string msg = err ? err : "unknown tinyexr error";
            if (err)
                FreeEXRErrorMessage(err);
            throw Error(fmt::format("cannot write EXR: {}", msg), path.string());
        }
    });
}

void save_image(const fs::path& path, const Image& image, const ToneMap& tm) {
    const std::string ext = lower_extension(path);
    if (ext == ".exr")
        save_exr(path, image);
    else if (ext == ".png")
        save_png(path, image, tm);
    else
        throw Error(fmt::format("unknown image extension '{}'; use .png or .exr", ext), path.string());
}

Image load_image(const fs::path& path) {
    const std::string ext = lower_extension(path);
    std::error_code ec;
    if (!fs::exists(path, ec))
        throw Error("file not found", path.string());
    if (ext == ".exr") {
        float* rgba = nullptr;
        int w = 0, h = 0;
        const char* err = nullptr;
        if (LoadEXR(&rgba, &w, &h, path.c_str(), &err) != TINYEXR_SUCCESS) {
            std::string msg = err ? err : "unknown tinyexr error";
            if (err)
                FreeEXRErrorMessage(err);
            throw Error(fmt::format("cannot read EXR: {}", msg), path.string());
        }
        std::unique_ptr<float, decltype(&std::free)> guard(rgba, &std::free);
        Image img(w, h);
        for (std::size_t i = 0; i < std::size_t(w) * std::size_t(h); ++i)
            for (int c = 0; c < 3; ++c)
                img.rgb[i * 3 + std::size_t(c)] = rgba[i * 4 + std::size_t(c)];
        return img;
    }
    const std::string data = read_file(path, std::uint64_t(1) << 30);
    int w = 0, h = 0, comp = 0;
    if (ext == ".hdr") { // Radiance RGBE: linear radiance
        float* f = stbi_loadf_from_memory(reinterpret_cast<const stbi_uc*>(data.data()), int(data.size()), &w, &h,
                                          &comp, 3);
        if (!f)
            throw Error(fmt::format("cannot decode Radiance HDR image: {}", stbi_failure_reason()), path.string());
        std::unique_ptr<float, void (*)(void*)> guard(f, stbi_image_free);
        Image img(w, h);
        std::copy(f, f + img.rgb.size(), img.rgb.begin());
        return img;
    }
    unsigned char* px = stbi_load_from_memory(reinterpret_cast<const stbi_uc*>(data.data()), int(data.size()), &w,
                                              &h, &comp, 3);
    if (!px)
        throw Error(fmt::format("cannot decode image: {}", stbi_failure_reason()), path.string());
    std::unique_ptr<unsigned char, void (*)(void*)> guard(px, stbi_image_free);
    Image img(w, h);
    for (std::size_t i = 0; i < img.rgb.size(); ++i)
        img.rgb[i] = srgb_to_linear(float(px[i]) / 255.0f);
    return img;
}

} // namespace skybake
