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
#include "sky/planet_shadow_hd.h"
#include "sky/sky_hd.h"

namespace skybake::neural {

constexpr int kInputs = 4;      // the sky function's arguments
constexpr int kMaxInputs = 5;   // and an aerosol family's amount (MlpHD::family)
constexpr int kOutputs = 4;     // the seed's outputs: R, G, B, M
constexpr int kMaxTerms = 4;    // phase-factored: one RGB term per scattering component
constexpr int kMaxOutputs = 3 * kMaxTerms + 3; // and residual outputs' multiple-scattering term
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
enum : int { kOutputsRadiance = 0, kOutputsPhaseFactored = 1, kOutputsResidual = 2 };
// Residual outputs: steps of the analytic march per lit part of the view ray,
// and the half range of the log ratio the network encodes (nats).
constexpr int kResidualSteps = 4;
constexpr float kResidualRange = 2.0f;
// Their multiple-scattering term's log range: 12 decades (nats), down to the
// sky of a sun 20° below the horizon (which the sky's own 6 would cut).
constexpr float kMultipleLogRange = 27.6310211f;
// Or, as a correction of an isotropic march (analytic_multiple), within the
// terms' e^±kResidualRange: the march's steps over the whole view ray, and the
// degrees of ln ψ's polynomial in altitude and in the sun's cosine.
constexpr int kMultipleSteps = 4;
constexpr int kPsiAltitudeDegree = 2, kPsiSunDegree = 6;
constexpr int kPsiCoefficients = (kPsiAltitudeDegree + 1) * (kPsiSunDegree + 1);

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
    // Residual: the analytic march's atmosphere, its exponential components
    // (scale height km, extinction 1/km) and per term the component and its
    // scattering (1/km).
    int ext_count = 0;
    float ext_height[kMaxTerms] = {};
    float ext_beta[kMaxTerms][3] = {};
    int term_ext[kMaxTerms] = {};
    float term_beta[kMaxTerms][3] = {};
    // and with multiple scattering, the log-encoded term after the others.
    int multiple = 0;
    float multiple_max[3] = {};
    // The term as a correction of an isotropic march (analytic_multiple):
    // ln ψ per channel, a polynomial in altitude and the sun's cosine
    // (psi_log); multiple_march 0: the term log-encoded below multiple_max.
    int multiple_march = 0;
    float psi_mu_min = -0.5f;
    float psi[3][kPsiCoefficients] = {};
    // An aerosol family (residual outputs): the network's fifth input is
    // family_a ln(aerosol) + family_b (−1 to 1 over the trained range), and the
    // march scales the extinction of exponential component family_ext and the
    // scattering of term family_term by aerosol, a multiple of the
    // atmosphere's amount chosen at run time.
    int family = 0;
    int family_ext = 0, family_term = 0;
    float family_a = 0.0f, family_b = 0.0f;
    float aerosol = 1.0f;
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

// The network's encoded outputs (m.outputs of them) for its width[0] inputs.
SKYBAKE_HD_INLINE void mlp_forward(const MlpHD& m, const float in[kMaxInputs], float* enc) {
    if (m.subnets == 1) {
        mlp_subnet_forward(m, m.weights, in, enc);
        return;
    }
    for (int s = 0; s < m.subnets; ++s)
        mlp_subnet_forward(m, m.weights + s * m.subnet_params, in, enc + s);
}

constexpr float kHorizonGap = 0.25f, kHorizonSpan = 1.0f - kHorizonGap;

// The observer and its view ray in km: altitude h = −H ln ρ0 in [0, Rtop −
// R0] (H: scale height of the first component), r = R0 + h, ρ = √(r² − R0²)
// and the length d of the ray to where it leaves the atmosphere or meets the
// ground (ground: it does).
struct ViewRayHD {
    float h, r, rho, d;
    bool ground;
};
SKYBAKE_HD_INLINE ViewRayHD view_ray_at(const MlpHD& m, float cos_view_zenith, float h) {
    ViewRayHD v;
    const float top = m.Rtop - m.R0;
    v.h = h > 0.0f ? (h < top ? h : top) : 0.0f;
    v.r = m.R0 + v.h;
    v.rho = sqrtf(v.h * (2.0f * m.R0 + v.h)); // √(r² − R0²)
    const float rc = v.r * cos_view_zenith;
    const float arc = fabsf(rc);
    v.ground = cos_view_zenith < 0.0f && arc >= v.rho;
    if (v.ground) {
        const float disc = (arc - v.rho) * (arc + v.rho); // r² cos² − ρ²
        v.d = -rc - sqrtf(disc > 0.0f ? disc : 0.0f);
    } else {
        const float disc = rc * rc + (top - v.h) * (2.0f * m.R0 + top + v.h); // r² cos² + Rtop² − r²
        v.d = -rc + sqrtf(disc > 0.0f ? disc : 0.0f);
    }
    return v;
}
SKYBAKE_HD_INLINE ViewRayHD view_ray(const MlpHD& m, float cos_view_zenith, float density) {
    return view_ray_at(m, cos_view_zenith, -m.scale_height * logf(density));
}

// ln x with relative accuracy near 1 as well: 2 atanh((x − 1)/(x + 1)) by
// its series there (GLSL's log is only accurate to 2⁻²¹ absolute on [0.5, 2],
// which is a relative error of 1e-3 in the altitude of an observer a few
// metres above the ground, and in the length of its short rays down).
SKYBAKE_HD_INLINE float log_density(float x) {
    const float u = (x - 1.0f) / (x + 1.0f), u2 = u * u;
    return x > 0.97f ? 2.0f * u * (1.0f + u2 * (0.333333343f + u2 * 0.2f)) : logf(x);
}

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
// An aerosol family adds in4 = family_a ln(aerosol) + family_b.
SKYBAKE_HD_INLINE void encode_inputs(const MlpHD& m, float cos_view_zenith, float cos_view_sun, float cos_sun_zenith,
                                     float density, float in[kMaxInputs]) {
    in[1] = cos_view_sun;
    in[2] = cos_sun_zenith;
    if (m.family)
        in[4] = m.family_a * logf(m.aerosol) + m.family_b;
    if (m.inputs != kInputsHorizon) {
        in[0] = cos_view_zenith;
        in[3] = density;
        return;
    }
    const float top = m.Rtop - m.R0;
    const ViewRayHD v = view_ray(m, cos_view_zenith, density);
    const float H = sqrtf(top * (2.0f * m.R0 + top)); // √(Rtop² − R0²)
    if (v.ground) {
        const float span = v.rho - v.h;
        const float t = span > 0.0f ? (v.d - v.h) / span : 0.0f;
        in[0] = -(kHorizonGap + kHorizonSpan * (t > 0.0f ? (t < 1.0f ? t : 1.0f) : 0.0f));
    } else {
        const float span = v.rho + H - (top - v.h);
        const float t = span > 0.0f ? (v.d - (top - v.h)) / span : 0.0f;
        in[0] = kHorizonGap + kHorizonSpan * (t > 0.0f ? (t < 1.0f ? t : 1.0f) : 0.0f);
    }
    in[3] = 2.0f * v.rho / H - 1.0f;
}

// [SECTION] Residual outputs: an analytic single scattering the network corrects
//
// The network's outputs are log ratios to a cheap analytic single scattering
// per phase term (analytic_terms), a few-step march in the spirit of O'Neil's
// GPU Gems 2 sky shader, with three changes that make it follow the sky at
// every altitude and at twilight:
//  - the sun's optical depth at each step is ρ H Ch(x, χ) with Chapman's
//    function in closed form (chapman_function); below the local horizon,
//    the whole grazing ray through its periapsis less the half behind;
//  - the march covers only the ray's lit parts: the planet's shadow of a
//    parallel sun is one interval of the ray (shadow_span), so up to two lit
//    parts of kResidualSteps midpoint steps each;
//  - the view's optical depth is a trapezoid sum over the same points; for
//    an aerosol family, whose hazy members put optical depths of tens on a
//    grazing ray that four trapezoids miss by factors of e^7, the
//    difference of Chapman integrals from the observer to each point
//    (chapman_segment) instead.
// Only the exponential components take part (ozone-like tents and constant
// shells are left to the network). The network's output x per term and
// channel is S = A exp(R (x − 0.5)/0.45), R = kResidualRange.

// The shadow interval of the ray's [0, d] (sky/planet_shadow_hd.h's, written
// in float with cancellation-free terms so that the exported shaders repeat it
// operation for operation): behind the terminator plane, r μs + t ν < 0, and
// inside the cylinder of radius R0 along the sun, A t² + B t + C < 0 with
// A = (1 − ν)(1 + ν), B = 2 r (μ − μs ν), C = (ρ − r μs)(ρ + r μs).
// True with [lo, hi], lo < hi, where some of it is in shadow.
SKYBAKE_HD_INLINE bool shadow_span(float r, float rho, float mu, float nu, float mu_s, float d, float& lo,
                                   float& hi) {
    lo = 0.0f;
    hi = d;
    const float c = r * mu_s;
    if (!sky::narrow_to_negative(c, nu, lo, hi))
        return false;
    const float A = (1.0f - nu) * (1.0f + nu), B = 2.0f * r * (mu - mu_s * nu), C = (rho - c) * (rho + c);
    if (A <= 1e-12f) { // along the sun: B t + C < 0
        if (!sky::narrow_to_negative(C, B, lo, hi))
            return false;
    } else {
        const float D = B * B - 4.0f * A * C;
        if (!(D > 0.0f))
            return false;
        const float q = -0.5f * (B + (B < 0.0f ? -sqrtf(D) : sqrtf(D)));
        const float ta = q / A, tb = q != 0.0f ? C / q : -ta;
        lo = lo > (ta < tb ? ta : tb) ? lo : (ta < tb ? ta : tb);
        hi = hi < (ta < tb ? tb : ta) ? hi : (ta < tb ? tb : ta);
    }
    return lo < hi;
}

// The altitude of the periapsis of a ray from altitude h at cos χ < 0 to
// the zenith: (R0 + h) sin χ − R0, as h sin χ − R0 cos²χ/(1 + sin χ), which
// keeps float's digits (the first form is a difference of two 6,000 km
// numbers); at least 0.
SKYBAKE_HD_INLINE float periapsis_altitude(float h, float R0, float cos_chi) {
    const float s2 = (1.0f - cos_chi) * (1.0f + cos_chi);
    const float s = sqrtf(s2 > 0.0f ? s2 : 0.0f);
    const float h0 = h * s - R0 * (cos_chi * cos_chi) / (1.0f + s);
    return h0 > 0.0f ? h0 : 0.0f;
}

// Chapman's function for a planet of radius R0 + h in scale heights H,
// Ch(x, χ) with x = (R0 + h)/H and cos χ ≥ 0, as sqrt(πx/2) erfcx(y),
// y = sqrt(x/2) cos χ (the large-x form, errors of order 1/x: x is 800 for
// air and 5,000 for aerosols on Earth), erfcx by Börjesson and Sundberg's
// approximation (IEEE Trans. Commun. 27(3), 1979; a = 0.339, b = 5.510, 0.3%
// at worst). With k = sqrt(x) it folds to k/((1 − a) k cos χ + a sqrt(k² cos²χ + b)).
SKYBAKE_HD_INLINE float chapman_function(float h, float R0, float H, float cos_chi) {
    const float k = sqrtf((R0 + h) / H), kc = k * cos_chi;
    return k / (0.661f * kc + 0.339f * sqrtf(kc * kc + 5.51f));
}

// ∫ ρ ds (km) from altitude h towards cos χ to infinity, ρ = exp(−h/H) given
// as rho_h: ρ H Ch above the horizon; below it the whole grazing ray through
// the periapsis h0 less the half behind, 2 ρ(h0) H Ch(x0, 90°) − ρ H Ch(x, π − χ).
SKYBAKE_HD_INLINE float chapman_depth(float h, float R0, float H, float cos_chi, float rho_h) {
    if (cos_chi >= 0.0f)
        return H * rho_h * chapman_function(h, R0, H, cos_chi);
    const float h0 = periapsis_altitude(h, R0, cos_chi);
    return H * (2.0f * expf(-h0 / H) * chapman_function(h0, R0, H, 0.0f) -
                rho_h * chapman_function(h, R0, H, -cos_chi));
}

// ∫ ρ dt over a part [a, b] of a view ray, for an exponential component of
// scale height H, from the altitudes and view cosines at its ends:
// differences of chapman_depth, with the periapsis term (where the part
// passes it) counted once. The view's cosine only grows along the ray.
SKYBAKE_HD_INLINE float chapman_segment(float R0, float H, float ha, float ca, float rho_a, float hb, float cb,
                                        float rho_b) {
    // ρ H Ch(x, |cos|) at each end: forward depth above the horizon, backward below.
    const float fa = H * rho_a * chapman_function(ha, R0, H, fabsf(ca));
    const float fb = H * rho_b * chapman_function(hb, R0, H, fabsf(cb));
    if (ca >= 0.0f)
        return fa - fb; // both ends above their horizons: forward(a) − forward(b)
    if (cb < 0.0f)
        return fb - fa; // both below: backward(b) − backward(a)
    // Through the periapsis: 2 ρ(h0) H Ch(x0, 90°) − backward(a) − forward(b).
    const float h0 = periapsis_altitude(ha, R0, ca);
    return 2.0f * H * expf(-h0 / H) * chapman_function(h0, R0, H, 0.0f) - fa - fb;
}

// view_ray with the altitude from log_density and the ray's length without
// view_ray's cancellation (a short ray to the ground, or up from near the
// top): the root's other form.
SKYBAKE_HD_INLINE ViewRayHD view_ray_precise(const MlpHD& m, float cos_view_zenith, float density) {
    ViewRayHD v = view_ray_at(m, cos_view_zenith, -m.scale_height * log_density(density));
    const float rc = v.r * cos_view_zenith, arc = fabsf(rc), top = m.Rtop - m.R0;
    if (v.ground) {
        const float disc = (arc - v.rho) * (arc + v.rho);
        v.d = v.rho * v.rho / (arc + sqrtf(disc > 0.0f ? disc : 0.0f));
    } else if (rc > 0.0f) {
        const float k = (top - v.h) * (2.0f * m.R0 + top + v.h); // Rtop² − r²
        const float disc = rc * rc + k;
        v.d = k / (rc + sqrtf(disc > 0.0f ? disc : 0.0f));
    }
    return v;
}

// True for an observer above the top (the inputs see it at the top) whose
// ray misses the atmosphere: it sees no air.
SKYBAKE_HD_INLINE bool misses_atmosphere(const MlpHD& m, float cos_view_zenith, float density) {
    const float top = m.Rtop - m.R0, hr = -m.scale_height * log_density(density);
    const float r = m.R0 + hr, rt = m.R0 + top;
    const float s2 = (1.0f - cos_view_zenith) * (1.0f + cos_view_zenith);
    return hr > top && (cos_view_zenith >= 0.0f || r * r * s2 >= rt * rt);
}

// The analytic single scattering A per phase term and channel (1/sr per unit
// sun irradiance, without the phase function) into base[3 k + c]. In each lit
// part the midpoint sum of each component's density is scaled to its
// Chapman integral (chapman_segment) where the part spans scale heights, so
// that a steep profile (aerosols, a 1.2 km scale height, on a 100 km ray) is
// not lost between the steps.
// analytic_terms along the view ray v (view_ray_precise), adding into base,
// which the caller has zeroed.
SKYBAKE_HD_INLINE void analytic_terms_along(const MlpHD& m, const ViewRayHD& v, float cos_view_zenith,
                                            float cos_view_sun, float cos_sun_zenith, float* base) {
    // The family's aerosol amount scales its component's coefficients.
    float ext_beta[kMaxTerms][3], term_beta[kMaxTerms][3];
    for (int e = 0; e < m.ext_count; ++e)
        for (int c = 0; c < 3; ++c)
            ext_beta[e][c] = m.family && e == m.family_ext ? m.ext_beta[e][c] * m.aerosol : m.ext_beta[e][c];
    for (int k = 0; k < m.terms; ++k)
        for (int c = 0; c < 3; ++c)
            term_beta[k][c] = m.family && k == m.family_term ? m.term_beta[k][c] * m.aerosol : m.term_beta[k][c];
    float lo, hi;
    const bool shadow = shadow_span(v.r, v.rho, cos_view_zenith, cos_view_sun, cos_sun_zenith, v.d, lo, hi);
    const float rho2 = v.rho * v.rho, two_r_mu = 2.0f * v.r * cos_view_zenith;
    float prev[kMaxTerms], obs[kMaxTerms], tau[3] = {0.0f, 0.0f, 0.0f}, t_prev = 0.0f;
    for (int e = 0; e < m.ext_count; ++e)
        prev[e] = obs[e] = expf(-v.h / m.ext_height[e]);
    for (int part = 0; part < 2; ++part) {
        const float a = part == 0 ? 0.0f : (shadow ? hi : v.d);
        const float b = part == 0 ? (shadow ? lo : v.d) : v.d;
        if (!(b > a))
            continue;
        const float dt = (b - a) * (1.0f / float(kResidualSteps));
        float sum_rho[kMaxTerms] = {}, part_sum[kMaxOutputs] = {};
        // The part's ends (altitude, radius, view cosine) and its lowest altitude.
        float h_end[3], r_end[2], c_end[2];
        for (int j = 0; j < 3; ++j) {
            float t = j == 0 ? a : b;
            if (j == 2) { // where the ray passes closest to the centre, clamped to the part
                t = -v.r * cos_view_zenith;
                t = t < a ? a : (t > b ? b : t);
            }
            float q = rho2 + t * (two_r_mu + t); // |p|² − R0²
            q = q > 0.0f ? q : 0.0f;
            h_end[j] = q / (sqrtf(q + m.R0 * m.R0) + m.R0);
            if (j < 2) {
                r_end[j] = m.R0 + h_end[j];
                c_end[j] = (v.r * cos_view_zenith + t) / r_end[j];
            }
        }
        for (int k = 0; k < kResidualSteps; ++k) {
            const float t = a + (float(k) + 0.5f) * dt;
            float q = rho2 + t * (two_r_mu + t);
            q = q > 0.0f ? q : 0.0f;
            const float hp = q / (sqrtf(q + m.R0 * m.R0) + m.R0);
            const float rp = m.R0 + hp;
            const float cos_chi = (v.r * cos_sun_zenith + t * cos_view_sun) / rp;
            float dens[kMaxTerms], sun[3] = {0.0f, 0.0f, 0.0f};
            if (m.family) // the view's depth from the observer, as Chapman integrals (see below)
                tau[0] = tau[1] = tau[2] = 0.0f;
            for (int e = 0; e < m.ext_count; ++e) {
                dens[e] = expf(-hp / m.ext_height[e]);
                sum_rho[e] += dens[e] * dt;
                const float view = m.family ? chapman_segment(m.R0, m.ext_height[e], v.h, cos_view_zenith, obs[e], hp,
                                                              (v.r * cos_view_zenith + t) / rp, dens[e])
                                            : 0.5f * (dens[e] + prev[e]) * (t - t_prev);
                const float depth = chapman_depth(hp, m.R0, m.ext_height[e], cos_chi, dens[e]);
                for (int c = 0; c < 3; ++c) {
                    tau[c] += ext_beta[e][c] * view;
                    sun[c] += ext_beta[e][c] * depth;
                }
                prev[e] = dens[e];
            }
            t_prev = t;
            for (int c = 0; c < 3; ++c) {
                const float tr = expf(-(tau[c] + sun[c])) * dt;
                for (int k2 = 0; k2 < m.terms; ++k2)
                    part_sum[3 * k2 + c] += term_beta[k2][c] * dens[m.term_ext[k2]] * tr;
            }
        }
        for (int k2 = 0; k2 < m.terms; ++k2) {
            const int e = m.term_ext[k2];
            const float H = m.ext_height[e];
            const float exact = chapman_segment(m.R0, H, h_end[0], c_end[0], expf(-h_end[0] / H), h_end[1], c_end[1],
                                                expf(-h_end[1] / H));
            // The Chapman integral where the part spans scale heights (the
            // steps miss the density's peak), the steps' sum where it spans
            // little (the steps are exact, and the integral, a difference of
            // two depths, is all rounding): g, the scale heights the density
            // climbs and falls along the part, blends them between 0.5 and 2.5.
            const float g = (h_end[0] + h_end[1] - 2.0f * h_end[2]) / H;
            float w = (g - 0.5f) * 0.5f;
            w = w > 0.0f ? (w < 1.0f ? w : 1.0f) : 0.0f;
            w = w * w * (3.0f - 2.0f * w);
            const float ratio = sum_rho[e] > 0.0f && exact > 0.0f ? exact / sum_rho[e] : 1.0f;
            const float scale = 1.0f + w * (ratio - 1.0f);
            for (int c = 0; c < 3; ++c)
                base[3 * k2 + c] += scale * part_sum[3 * k2 + c];
        }
    }
}

SKYBAKE_HD_INLINE void analytic_terms(const MlpHD& m, float cos_view_zenith, float cos_view_sun, float cos_sun_zenith,
                                      float density, float* base) {
    for (int i = 0; i < 3 * m.terms; ++i)
        base[i] = 0.0f;
    if (misses_atmosphere(m, cos_view_zenith, density))
        return;
    analytic_terms_along(m, view_ray_precise(m, cos_view_zenith, density), cos_view_zenith, cos_view_sun,
                         cos_sun_zenith, base);
}

// [SECTION] Residual outputs' multiple-scattering term: an isotropic march
//
// Hillaire 2020's approximation of the light scattered more than once: every
// point of the view ray scatters towards the observer, isotropically, the
// mean radiance ψ of the sky around it, which depends only on its altitude
// and the sun's cosine there. Here ψ is the mean of the model's own sky (single
// plus multiple scattering) over the sphere, fitted at training time as ln ψ
// = Σ a_ij x^i y^j per channel, x = 2h/(Rtop − R0) − 1, y the sun's cosine
// mapped from [psi_mu_min, 1] onto [−1, 1], both clamped (psi_log). The march
// takes kMultipleSteps midpoints over the whole ray (lit or not), each
// adding ψ σs dt e^(−τ) (1 − e^(−Δτ))/Δτ with the step's view depth Δτ a
// trapezoid: exact for a step of constant coefficients however thick. The
// network's outputs x are log ratios to it: S = M exp(R (x − 0.5)/0.45),
// R = kResidualRange, as for the terms.
SKYBAKE_HD_INLINE float psi_log(const MlpHD& m, int c, float h, float mu_s) {
    float x = 2.0f * h / (m.Rtop - m.R0) - 1.0f;
    float y = (2.0f * mu_s - 1.0f - m.psi_mu_min) / (1.0f - m.psi_mu_min);
    x = x > -1.0f ? (x < 1.0f ? x : 1.0f) : -1.0f;
    y = y > -1.0f ? (y < 1.0f ? y : 1.0f) : -1.0f;
    float acc = 0.0f;
    for (int i = kPsiAltitudeDegree; i >= 0; --i) {
        float row = 0.0f;
        for (int j = kPsiSunDegree; j >= 0; --j)
            row = row * y + m.psi[c][i * (kPsiSunDegree + 1) + j];
        acc = acc * x + row;
    }
    return acc;
}

// The march M = Σ_k w_k ψ(h_k, μs_k) per channel along the view ray v
// (view_ray_precise), w_k = σs dt e^(−τ) (1 − e^(−Δτ))/Δτ at step k's
// midpoint, adding into out[0..2], which the caller has zeroed.
SKYBAKE_HD_INLINE void analytic_multiple_along(const MlpHD& m, const ViewRayHD& v, float cos_view_zenith,
                                               float cos_view_sun, float cos_sun_zenith, float* out) {
    const float rho2 = v.rho * v.rho, two_r_mu = 2.0f * v.r * cos_view_zenith;
    const float dt = v.d * (1.0f / float(kMultipleSteps));
    float prev[kMaxTerms], tau[3] = {0.0f, 0.0f, 0.0f};
    for (int e = 0; e < m.ext_count; ++e)
        prev[e] = expf(-v.h / m.ext_height[e]);
    for (int k = 0; k < kMultipleSteps; ++k) {
        float hp[2];
        for (int j = 0; j < 2; ++j) { // the step's midpoint, then its end
            const float t = (float(k) + (j == 0 ? 0.5f : 1.0f)) * dt;
            float q = rho2 + t * (two_r_mu + t); // |p|² − R0²
            q = q > 0.0f ? q : 0.0f;
            hp[j] = q / (sqrtf(q + m.R0 * m.R0) + m.R0);
        }
        const float mu_s = (v.r * cos_sun_zenith + (float(k) + 0.5f) * dt * cos_view_sun) / (m.R0 + hp[0]);
        float mid[kMaxTerms], end[kMaxTerms];
        for (int e = 0; e < m.ext_count; ++e) {
            mid[e] = expf(-hp[0] / m.ext_height[e]);
            end[e] = expf(-hp[1] / m.ext_height[e]);
        }
        for (int c = 0; c < 3; ++c) {
            float sca = 0.0f, dtau = 0.0f;
            for (int e = 0; e < m.ext_count; ++e)
                dtau += m.ext_beta[e][c] * 0.5f * (prev[e] + end[e]) * dt;
            for (int k2 = 0; k2 < m.terms; ++k2)
                sca += m.term_beta[k2][c] * mid[m.term_ext[k2]];
            // (1 − e^(−Δτ))/Δτ, by its series where the difference would cancel
            // (shaders' exp is a few ulp off; 1/Δτ would magnify that).
            const float f = dtau > 0.1f ? (1.0f - expf(-dtau)) / dtau
                                        : 1.0f - dtau * (0.5f - dtau * (0.166666672f - dtau * 0.0416666679f));
            const float w = expf(-tau[c]) * sca * dt * f;
            tau[c] += dtau;
            out[c] += w * expf(psi_log(m, c, hp[0], mu_s));
        }
        for (int e = 0; e < m.ext_count; ++e)
            prev[e] = end[e];
    }
}

// The march M per channel (1/sr per unit sun irradiance) into out[0..2].
SKYBAKE_HD_INLINE void analytic_multiple(const MlpHD& m, float cos_view_zenith, float cos_view_sun,
                                         float cos_sun_zenith, float density, float* out) {
    out[0] = out[1] = out[2] = 0.0f;
    if (misses_atmosphere(m, cos_view_zenith, density))
        return;
    analytic_multiple_along(m, view_ray_precise(m, cos_view_zenith, density), cos_view_zenith, cos_view_sun,
                            cos_sun_zenith, out);
}

// The residual outputs' analytic parts: analytic_terms into base[0, 3 terms),
// and for a multiple-scattering term marched, analytic_multiple after them.
SKYBAKE_HD_INLINE void analytic_base(const MlpHD& m, float cos_view_zenith, float cos_view_sun, float cos_sun_zenith,
                                     float density, float* base) {
    const bool marched = m.multiple && m.multiple_march;
    for (int i = 0; i < 3 * m.terms + (marched ? 3 : 0); ++i)
        base[i] = 0.0f;
    if (misses_atmosphere(m, cos_view_zenith, density))
        return;
    const ViewRayHD v = view_ray_precise(m, cos_view_zenith, density); // once for both marches
    analytic_terms_along(m, v, cos_view_zenith, cos_view_sun, cos_sun_zenith, base);
    if (marched)
        analytic_multiple_along(m, v, cos_view_zenith, cos_view_sun, cos_sun_zenith, base + 3 * m.terms);
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
//  residual:       Σ_k P_k(cos β0) A_k exp(R (x_k − 0.5)/0.45), A_k = base[3k..3k+2]
//                  (analytic_terms; required for residual outputs).
SKYBAKE_HD_INLINE glm::vec3 decode_sky(const MlpHD& m, const float* enc, float cos_view_sun = 1.0f,
                                       const float* base = nullptr) {
    if (m.output_kind == kOutputsResidual) {
        glm::vec3 c(0.0f);
        const float scale = kResidualRange / (0.5f * kEncodeScale);
        for (int k = 0; k < m.terms; ++k) {
            const float p = sky::phase_value(m.term_phase[k], m.term_g[k], cos_view_sun);
            c.x += p * base[3 * k + 0] * expf(scale * (enc[3 * k + 0] - 0.5f));
            c.y += p * base[3 * k + 1] * expf(scale * (enc[3 * k + 1] - 0.5f));
            c.z += p * base[3 * k + 2] * expf(scale * (enc[3 * k + 2] - 0.5f));
        }
        if (m.multiple && m.multiple_march) { // the light scattered more than once, a correction of its march
            const float* x = enc + 3 * m.terms;
            const float* a = base + 3 * m.terms;
            const float ms = kResidualRange / (0.5f * kEncodeScale);
            c.x += a[0] * expf(ms * (x[0] - 0.5f));
            c.y += a[1] * expf(ms * (x[1] - 0.5f));
            c.z += a[2] * expf(ms * (x[2] - 0.5f));
        } else if (m.multiple) { // the light scattered more than once, log-encoded
            const float* x = enc + 3 * m.terms;
            c.x += decode_log(x[0], m.multiple_max[0], kMultipleLogRange);
            c.y += decode_log(x[1], m.multiple_max[1], kMultipleLogRange);
            c.z += decode_log(x[2], m.multiple_max[2], kMultipleLogRange);
        }
        return c;
    }
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
    float in[kMaxInputs];
    encode_inputs(m, cos_view_zenith, cos_view_sun, cos_sun_zenith, density, in);
    float enc[kMaxOutputs];
    mlp_forward(m, in, enc);
    if (m.output_kind == kOutputsResidual) {
        float base[kMaxOutputs];
        analytic_base(m, cos_view_zenith, cos_view_sun, cos_sun_zenith, density, base);
        return decode_sky(m, enc, cos_view_sun, base);
    }
    return decode_sky(m, enc, cos_view_sun);
}

} // namespace skybake::neural
