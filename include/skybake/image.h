// skybake/image.h: images in linear light, PNG and EXR files.
//
// [SECTION] Image type
// [SECTION] Tone mapping (HDR -> 8-bit sRGB)
// [SECTION] Files
//
// Images are linear RGB float, row-major, top row first, 3 floats per pixel.
// EXR files keep the linear values. PNG files are 8-bit sRGB: linear values
// go through tone_map() first (see docs/images.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace skybake {

// [SECTION] Image type ---------------------------------------------------------
struct Image {
    int width = 0;
    int height = 0;
    std::vector<float> rgb; // width * height * 3, linear

    Image() = default;
    Image(int w, int h) : width(w), height(h), rgb(std::size_t(w) * std::size_t(h) * 3, 0.0f) {}
    float* pixel(int x, int y) { return rgb.data() + (std::size_t(y) * std::size_t(width) + std::size_t(x)) * 3; }
    const float* pixel(int x, int y) const {
        return rgb.data() + (std::size_t(y) * std::size_t(width) + std::size_t(x)) * 3;
    }
};

// [SECTION] Tone mapping ---------------------------------------------------------
enum class ToneCurve {
    Clamp,    // clamp(x, 0, 1): for images already in [0, 1]
    Reinhard, // x / (1 + x), per channel
    Aces,     // Narkowicz 2015 fit of the ACES filmic curve (default)
};

struct ToneMap {
    // Exposure in stops: linear values are multiplied by 2^exposure_ev.
    float exposure_ev = 0.0f;
    ToneCurve curve = ToneCurve::Aces;
};

// Parses "clamp", "reinhard" or "aces"; throws skybake::Error otherwise.
ToneCurve parse_tone_curve(const std::string& name);

// Linear value -> display value in [0, 1] (before the sRGB transfer function).
float tone_map_value(float linear, const ToneMap& tm);
// sRGB transfer function (IEC 61966-2-1) on [0, 1].
float linear_to_srgb(float linear);
float srgb_to_linear(float encoded);

// Exposure in stops that maps the 98th percentile of the image's luminance
// (Rec. 709 weights, positive finite pixels) to 1; 0 for a black image.
double auto_exposure_ev(const Image& image);

// Linear float image -> 8-bit sRGB, 3 bytes per pixel.
std::vector<std::uint8_t> to_srgb8(const Image& image, const ToneMap& tm = {});

// [SECTION] Files -----------------------------------------------------------------
// Writes by extension: ".exr" (linear float, lossless ZIP) or ".png" (8-bit
// sRGB through tm). Written to a temporary file and renamed when complete.
// Throws skybake::Error on an unknown extension, an empty image or I/O failure.
void save_image(const std::filesystem::path& path, const Image& image, const ToneMap& tm = {});
void save_exr(const std::filesystem::path& path, const Image& image);
void save_png(const std::filesystem::path& path, const Image& image, const ToneMap& tm = {});
// Writes an 8-bit sRGB buffer (3 bytes per pixel) as PNG.
void save_png_srgb8(const std::filesystem::path& path, int width, int height, const std::uint8_t* rgb);

// Writes one channel of linear values in [0, 1] (clamped; width * height,
// row-major, top row first) as a 16-bit greyscale PNG, without the sRGB
// curve: data such as an occlusion texture, which glTF reads linearly.
void save_png16_gray(const std::filesystem::path& path, int width, int height, const std::vector<float>& values);

// Reads an EXR or a Radiance .hdr (linear) or a PNG/JPEG (sRGB, decoded to linear).
// Throws skybake::Error on a missing or corrupt file, and on one whose
// header claims more than kMaxImagePixels pixels.
Image load_image(const std::filesystem::path& path);

// The largest image load_image() reads (a 16384 x 8192 map): the header is
// checked before any pixel is allocated, so that a few hostile bytes cannot
// make the loader allocate gigabytes.
inline constexpr std::uint64_t kMaxImagePixels = std::uint64_t(1) << 27;

// load_image() from a file's bytes. format: the file's extension ("exr",
// "hdr", "png", "jpg"; any case, with or without the dot): EXR goes to
// tinyexr, HDR to stb_image as linear floats, anything else to stb_image as
// 8-bit sRGB. name stands for the file in errors. Throws skybake::Error on an
// empty, corrupt or too large image (more than max_pixels).
Image load_image_from_memory(const void* data, std::size_t size, const std::string& format, const std::string& name,
                             std::uint64_t max_pixels = kMaxImagePixels);

} // namespace skybake
