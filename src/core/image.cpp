// Images in linear light and their tone mapping (skybake/image.h).
#include "skybake/image.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "skybake/error.h"
#include "skybake/names.h"

namespace skybake {

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

} // namespace skybake
