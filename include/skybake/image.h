// skybake/image.h: images in linear light, and their tone mapping (core:
// every module may use them; the files are skybake/image_io.h).
//
// [SECTION] Image type
// [SECTION] Tone mapping (HDR -> 8-bit sRGB)
//
// Images are linear RGB float, row-major, top row first, 3 floats per pixel.
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

} // namespace skybake
