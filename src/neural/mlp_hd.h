// The forward pass of the neural sky, shared by the CPU and a CUDA evaluator.
//
// Pietras K., Rudnicki M. GPU-based multi-layer perceptron as efficient method
// for approximation complex light models in per-vertex lighting (seed 000),
// section III (the network and its normalisation) and section VI (the vertex
// program: dot products, bias, f(x) = 1/(1 + 2^(2x)) via EX2 and RCP, and the
// final transformation (x − 0.05)/0.9 with x < 0.05 treated as 0).
//
// Plain structs and flat float arrays only, so that it compiles unchanged
// under nvcc (SKYBAKE_HD). The weight layout is the one of skybake/neural.h:
// per sub-network, per layer, W [out][in] row-major, then b [out].
#pragma once

#include <cmath>

#include <glm/vec3.hpp>

#include "core/hd.h"
#include "sky/sky_hd.h"

namespace skybake::neural {

constexpr int kInputs = 4;
constexpr int kOutputs = 4;     // the seed's outputs: R, G, B, M
constexpr int kMaxTerms = 4;    // phase-factored: one RGB term per scattering component
constexpr int kMaxOutputs = 3 * kMaxTerms;
constexpr int kMaxHidden = 7;              // hidden layers
constexpr int kMaxLayers = kMaxHidden + 1; // weight layers
constexpr int kMaxWidth = 128;
constexpr float kEncodeOffset = 0.05f;
constexpr float kEncodeScale = 0.9f;
// f(x) = 1/(1 + 2^(2x)) = σ(−kSlope x) with kSlope = 2 ln 2.
constexpr float kSlope = 1.38629436111989f;

enum : int { kBrightnessLinear = 0, kBrightnessLog = 1 };
// Values of skybake::InputEncoding and OutputEncoding.
enum : int { kInputsSeed = 0, kInputsHorizon = 1 };
enum : int { kOutputsRadiance = 0, kOutputsPhaseFactored = 1 };

struct MlpHD {
    const float* weights = nullptr; // subnets * subnet_params floats
    int subnets = 4;                // outputs: independent (R, G, B, M); 1: shared
    int layers = 3;                 // weight layers (hidden + 1)
    int width[kMaxLayers + 1] = {4, 8, 4, 1}; // width[0] = 4 inputs, width[layers] = outputs per sub-network
    int subnet_params = 81;
    int outputs = kOutputs;         // encoded outputs of the whole network
    int brightness = kBrightnessLog;
    float max_n = 1.0f;             // 1/sr
    float log_range = 13.8155106f;  // nats
    // Input encoding and the geometry the horizon inputs need (km).
    int inputs = kInputsSeed;
    float R0 = 6360.0f, Rtop = 6420.0f, scale_height = 8.0f;
    // Output encoding; phase-factored: per term its phase function (sky::phase_value's kind and g) and
    // per-channel maximum (1/sr).
    int output_kind = kOutputsRadiance;
    int terms = 0;
    int term_phase[kMaxTerms] = {};
    float term_g[kMaxTerms] = {};
    float term_max[kMaxTerms][3] = {};
};

SKYBAKE_HD_INLINE float seed_activation(float x) { return 1.0f / (1.0f + exp2f(2.0f * x)); }

// One sub-network: in[width[0]] -> out[width[layers]].
SKYBAKE_HD_INLINE void mlp_subnet_forward(const MlpHD& m, const float* w, const float* in, float* out) {
    float buf[2][kMaxWidth];
    const float* a = in;
    for (int l = 0; l < m.layers; ++l) {
        const int n_in = m.width[l], n_out = m.width[l + 1];
        const float* W = w;
        const float* b = w + n_out * n_in;
        float* z = l + 1 == m.layers ? out : buf[l & 1];
        for (int r = 0; r < n_out; ++r) {
            float s = 0.0f;
            for (int c = 0; c < n_in; ++c)
                s += W[r * n_in + c] * a[c];
            z[r] = seed_activation(s + b[r]);
        }
        a = z;
        w = b + n_out;
    }
}

// The network's encoded outputs (m.outputs of them) for its 4 inputs.
SKYBAKE_HD_INLINE void mlp_forward(const MlpHD& m, const float in[kInputs], float* enc) {
    if (m.subnets == 1) {
        mlp_subnet_forward(m, m.weights, in, enc);
        return;
    }
    for (int s = 0; s < m.subnets; ++s)
        mlp_subnet_forward(m, m.weights + s * m.subnet_params, in, enc + s);
}

constexpr float kHorizonGap = 0.25f, kHorizonSpan = 1.0f - kHorizonGap;

// The network's inputs from the sky function's arguments.
//  seed:    (cos α0, cos β0, cos θ0, ρ0) as they are.
//  horizon: altitude h = −H ln ρ0 (H: scale height of the first component),
//           r = R0 + h, ρ = √(r² − R0²), Ĥ = √(Rtop² − R0²); then
//   in0: the view ray's length d to where it leaves the atmosphere or meets
//        the ground, as in Bruneton 2017's texture mapping, t = (d − dmin)/
//        (dmax − dmin): up rays (dmin = Rtop − r, dmax = ρ + Ĥ) map to
//        g + (1 − g) t in [g, 1], ground rays (dmin = h, dmax = ρ) to
//        −(g + (1 − g) t) in [−1, −g], g = kHorizonGap. The horizon seen
//        from above is +1, from below −1: the cliff between them is as far
//        apart as the input allows. The zenith (g) and the nadir (−g), where
//        the two halves meet, are 2g apart, room for the network to go from
//        the bright zenith to the dark short rays below.
//   in1: cos β0.
//   in2: cos θ0. (The sun's elevation above the observer's dipped horizon,
//        (asin cos θ0 + atan(ρ/R0)) / (π/2), was tried and measured worse:
//        docs/neural.md.)
//   in3: 2 ρ/Ĥ − 1 (Bruneton's r coordinate: fine near the ground).
SKYBAKE_HD_INLINE void encode_inputs(const MlpHD& m, float cos_view_zenith, float cos_view_sun, float cos_sun_zenith,
                                     float density, float in[kInputs]) {
    in[1] = cos_view_sun;
    in[2] = cos_sun_zenith;
    if (m.inputs != kInputsHorizon) {
        in[0] = cos_view_zenith;
        in[3] = density;
        return;
    }
    const float top = m.Rtop - m.R0;
    float h = -m.scale_height * logf(density);
    h = h > 0.0f ? (h < top ? h : top) : 0.0f;
    const float r = m.R0 + h;
    const float rho = sqrtf(h * (2.0f * m.R0 + h));     // √(r² − R0²)
    const float H = sqrtf(top * (2.0f * m.R0 + top));   // √(Rtop² − R0²)
    const float rc = r * cos_view_zenith;
    const float arc = fabsf(rc);
    if (cos_view_zenith < 0.0f && arc >= rho) { // the ray meets the ground
        const float disc = (arc - rho) * (arc + rho);  // r² cos² − ρ²
        const float d = -rc - sqrtf(disc > 0.0f ? disc : 0.0f);
        const float span = rho - h;
        const float t = span > 0.0f ? (d - h) / span : 0.0f;
        in[0] = -(kHorizonGap + kHorizonSpan * (t > 0.0f ? (t < 1.0f ? t : 1.0f) : 0.0f));
    } else {
        const float disc = rc * rc + (top - h) * (2.0f * m.R0 + top + h); // r² cos² + Rtop² − r²
        const float d = -rc + sqrtf(disc > 0.0f ? disc : 0.0f);
        const float span = rho + H - (top - h);
        const float t = span > 0.0f ? (d - (top - h)) / span : 0.0f;
        in[0] = kHorizonGap + kHorizonSpan * (t > 0.0f ? (t < 1.0f ? t : 1.0f) : 0.0f);
    }
    in[3] = 2.0f * rho / H - 1.0f;
}

// Encoded value -> [0, ...): (x − 0.05)/0.9, values below 0.05 are 0.
SKYBAKE_HD_INLINE float decode_unit(float x) {
    const float v = (x - kEncodeOffset) * (1.0f / kEncodeScale);
    return v > 0.0f ? v : 0.0f;
}

// A log-encoded value: 0 below the offset (night), else max · e^(D (x' − 1)).
SKYBAKE_HD_INLINE float decode_log(float x, float max, float log_range) {
    const float v = (x - kEncodeOffset) * (1.0f / kEncodeScale);
    return v > 0.0f ? max * expf(log_range * (v - 1.0f)) : 0.0f;
}

// Radiance (1/sr) from the encoded outputs.
//  radiance:       (R, G, B) · N, N from the brightness output M.
//  phase-factored: Σ_k P_k(cos β0) S_k, each channel of S_k log-encoded.
SKYBAKE_HD_INLINE glm::vec3 decode_sky(const MlpHD& m, const float* enc, float cos_view_sun = 1.0f) {
    if (m.output_kind == kOutputsPhaseFactored) {
        glm::vec3 c(0.0f);
        for (int k = 0; k < m.terms; ++k) {
            const float p = sky::phase_value(m.term_phase[k], m.term_g[k], cos_view_sun);
            c.x += p * decode_log(enc[3 * k + 0], m.term_max[k][0], m.log_range);
            c.y += p * decode_log(enc[3 * k + 1], m.term_max[k][1], m.log_range);
            c.z += p * decode_log(enc[3 * k + 2], m.term_max[k][2], m.log_range);
        }
        return c;
    }
    const float mm = (enc[3] - kEncodeOffset) * (1.0f / kEncodeScale);
    if (!(mm > 0.0f))
        return glm::vec3(0.0f); // night
    const float n = m.brightness == kBrightnessLinear ? mm * m.max_n : m.max_n * expf(m.log_range * (mm - 1.0f));
    return glm::vec3(decode_unit(enc[0]) * n, decode_unit(enc[1]) * n, decode_unit(enc[2]) * n);
}

SKYBAKE_HD_INLINE glm::vec3 neural_sky(const MlpHD& m, float cos_view_zenith, float cos_view_sun,
                                       float cos_sun_zenith, float density) {
    float in[kInputs];
    encode_inputs(m, cos_view_zenith, cos_view_sun, cos_sun_zenith, density, in);
    float enc[kMaxOutputs];
    mlp_forward(m, in, enc);
    return decode_sky(m, enc, cos_view_sun);
}

} // namespace skybake::neural
