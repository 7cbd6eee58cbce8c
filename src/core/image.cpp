// Images in linear light and their tone mapping (skybake/image.h).
#include "skybake/image.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/shared_source.h"
#include "skybake/error.h"
#include "skybake/names.h"

namespace skybake {

namespace tone {
#include "core/tone_curve.h" // shared with the renderers' GLSL tone pass
} // namespace tone
static_assert(int(ToneCurve::Clamp) == tone::kToneClamp && int(ToneCurve::Reinhard) == tone::kToneReinhard &&
              int(ToneCurve::Aces) == tone::kToneAces);

namespace {
constexpr NamedValue<ToneCurve> kToneCurveNames[] = {
    {ToneCurve::Clamp, "clamp"}, {ToneCurve::Reinhard, "reinhard"}, {ToneCurve::Aces, "aces"}};
} // namespace

ToneCurve parse_tone_curve(const std::string& name) { return parse_name(kToneCurveNames, name, "tone curve", "curve"); }

float tone_map_value(float linear, const ToneMap& tm) {
    if (!std::isfinite(linear) || linear <= 0.0f)
        return linear > 0.0f ? 1.0f : 0.0f; // +inf -> white, NaN/negative -> black
    return tone::tone_curve(int(tm.curve), linear * std::exp2(tm.exposure_ev));
}

float linear_to_srgb(float v) { return tone::srgb_encode(v); }

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
