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

namespace skybake::neural {

constexpr int kInputs = 4;
constexpr int kOutputs = 4;
constexpr int kMaxHidden = 7;              // hidden layers
constexpr int kMaxLayers = kMaxHidden + 1; // weight layers
constexpr int kMaxWidth = 128;
constexpr float kEncodeOffset = 0.05f;
constexpr float kEncodeScale = 0.9f;
// f(x) = 1/(1 + 2^(2x)) = σ(−kSlope x) with kSlope = 2 ln 2.
constexpr float kSlope = 1.38629436111989f;

enum : int { kBrightnessLinear = 0, kBrightnessLog = 1 };

struct MlpHD {
    const float* weights = nullptr; // subnets * subnet_params floats
    int subnets = 4;                // 4: independent (R, G, B, M); 1: shared
    int layers = 3;                 // weight layers (hidden + 1)
    int width[kMaxLayers + 1] = {4, 8, 4, 1}; // width[0] = 4 inputs, width[layers] = outputs per sub-network
    int subnet_params = 81;
    int brightness = kBrightnessLog;
    float max_n = 1.0f;             // 1/sr
    float log_range = 13.8155106f;  // nats
};

// The seed's activation, as printed. Its vertex program computes
// 1/(1 + 2^(−2x)) = 1 − f(x) (MUL by −2.0, EX2, ADD 1, RCP): the same networks
// with the signs of every neuron's incoming weights and bias flipped.
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

// The four encoded outputs (R, G, B, M) for inputs (cos α0, cos β0, cos θ0, ρ0).
SKYBAKE_HD_INLINE void mlp_forward(const MlpHD& m, const float in[kInputs], float enc[kOutputs]) {
    if (m.subnets == 1) {
        mlp_subnet_forward(m, m.weights, in, enc);
        return;
    }
    for (int s = 0; s < m.subnets; ++s)
        mlp_subnet_forward(m, m.weights + s * m.subnet_params, in, enc + s);
}

// Encoded value -> [0, ...): (x − 0.05)/0.9, values below 0.05 are 0.
SKYBAKE_HD_INLINE float decode_unit(float x) {
    const float v = (x - kEncodeOffset) * (1.0f / kEncodeScale);
    return v > 0.0f ? v : 0.0f;
}

// Radiance (1/sr) from the encoded outputs: (R, G, B) · N.
SKYBAKE_HD_INLINE glm::vec3 decode_sky(const MlpHD& m, const float enc[kOutputs]) {
    const float mm = (enc[3] - kEncodeOffset) * (1.0f / kEncodeScale);
    if (!(mm > 0.0f))
        return glm::vec3(0.0f); // night
    const float n = m.brightness == kBrightnessLinear ? mm * m.max_n : m.max_n * expf(m.log_range * (mm - 1.0f));
    return glm::vec3(decode_unit(enc[0]) * n, decode_unit(enc[1]) * n, decode_unit(enc[2]) * n);
}

SKYBAKE_HD_INLINE glm::vec3 neural_sky(const MlpHD& m, float cos_view_zenith, float cos_view_sun,
                                       float cos_sun_zenith, float density) {
    const float in[kInputs] = {cos_view_zenith, cos_view_sun, cos_sun_zenith, density};
    float enc[kOutputs];
    mlp_forward(m, in, enc);
    return decode_sky(m, enc);
}

} // namespace skybake::neural
