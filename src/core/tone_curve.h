// The tone curves of skybake::tone_map_value (skybake/image.h) and the sRGB
// encoding, written once in the common subset of C++ and GLSL
// (core/shared_source.h): core/image.cpp includes this file, and the
// renderers' tone pass (src/render/shaders/screen_stages.glsl) embeds it.
//
// Reinhard E., Stark M., Shirley P., Ferwerda J. Photographic Tone
// Reproduction for Digital Images. SIGGRAPH 2002 (the global operator x/(1+x)).
// Narkowicz K. ACES Filmic Tone Mapping Curve. 2016 (the rational fit).
// IEC 61966-2-1:1999, sRGB (the encoding).
#ifndef SKYBAKE_CORE_TONE_CURVE_H
#define SKYBAKE_CORE_TONE_CURVE_H

// Values of skybake::ToneCurve.
const int kToneClamp = 0;
const int kToneReinhard = 1;
const int kToneAces = 2;

// Curve `curve` at x = linear value × 2^exposure_ev, clamped to [0, 1].
// NaN stays NaN (as std::clamp leaves it).
SKYBAKE_HD_INLINE float tone_curve(int curve, float x) {
    float y = x;
    if (curve == kToneReinhard)
        y = x / (1.0f + x);
    else if (curve == kToneAces)
        y = (x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f);
    return y < 0.0f ? 0.0f : (y > 1.0f ? 1.0f : y);
}

// The sRGB encoding of a linear value v, clamped to [0, 1] first.
SKYBAKE_HD_INLINE float srgb_encode(float v) {
    v = v < 0.0f ? 0.0f : (v > 1.0f ? 1.0f : v);
    return v <= 0.0031308f ? 12.92f * v : 1.055f * powf(v, 1.0f / 2.4f) - 0.055f;
}

#endif
