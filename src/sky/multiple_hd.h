// Look-up tables of multiple scattering, shared by the CPU and a CUDA
// evaluator, and by the double-precision precomputation (templates on T).
//
// Bruneton E. A Qualitative and Quantitative Evaluation of 8 Clear Sky
// Models. IEEE TVCG 2017, and its reference implementation "Precomputed
// Atmospheric Scattering" (section "Texture coordinates"): the 4D grid of
// scattered radiance over (r, μ, μs, ν), with μ split at the horizon so that
// rays that meet the ground and rays that do not are never interpolated
// together.
// Hillaire S. A Scalable and Production Ready Sky and Atmosphere Rendering
// Technique. EGSR 2020: the 2D table ψms(r, μs) of isotropic multiple
// scattering.
//
// Notation: r radius (km), μ cosine of the view direction to the local
// vertical, μs cosine of the sun direction to the local vertical, ν cosine of
// the view direction to the sun direction.
#pragma once

#include <cmath>

#include <glm/vec3.hpp>

#include "core/hd.h"

namespace skybake::sky {

enum : int { kMultipleNone = 0, kMultipleOrders = 1, kMultipleHillaire = 2 };

// The multiple-scattering state of an atmosphere (flat, for CPU and GPU).
// Every table holds RGB floats, node-centred: coordinate x in [0, 1] maps to
// index x (n − 1).
struct MultipleHD {
    int method = kMultipleNone;
    float mu_s_min = -0.2f; // the orders grid's lowest sun cosine; below it, values are those at mu_s_min
    // Orders ≥ 2 of scattered radiance (1/sr per unit sun irradiance) over the
    // grid nr × (2 nmu) × nmus × nnu (see grid4_index).
    const float* orders = nullptr;
    int nr = 0, nmu = 0, nmus = 0, nnu = 0;
    // Hillaire's ψms (1/sr per unit sun irradiance, isotropic phase included)
    // over psi_nr altitudes (uniform, ground to top) × psi_nmus sun cosines (uniform in [−1, 1]).
    const float* psi = nullptr;
    int psi_nr = 0, psi_nmus = 0;
    // Irradiance of the scattered sky light on a horizontal surface (per unit
    // sun irradiance; the direct sun excluded) over irr_nr altitudes × irr_nmus sun cosines.
    const float* irradiance = nullptr;
    int irr_nr = 0, irr_nmus = 0;
};

SKYBAKE_HD_INLINE float hd_sqrt(float x) { return sqrtf(x > 0.0f ? x : 0.0f); }
SKYBAKE_HD_INLINE double hd_sqrt(double x) { return sqrt(x > 0.0 ? x : 0.0); }
template <class T>
SKYBAKE_HD_INLINE T hd_clamp(T x, T lo, T hi) {
    return x < lo ? lo : (x > hi ? hi : x);
}

// Distance from radius r along a ray with cosine mu to the top Rt (r ≤ Rt).
template <class T>
SKYBAKE_HD_INLINE T distance_to_top(T r, T mu, T Rt) {
    return -r * mu + hd_sqrt(r * r * (mu * mu - T(1)) + Rt * Rt);
}

// The unit-range coordinates of a point of the 4D grid.
template <class T>
struct Grid4Coord {
    T xr, xmu, xmus, xnu;
    int ground; // 1: the ray meets the ground (the lower half of the μ axis)
};

// Bruneton 2017's mapping (x = 0..1 on each axis), without the texel-centre offsets.
template <class T>
SKYBAKE_HD_INLINE Grid4Coord<T> grid4_coordinates(T R0, T Rt, T mu_s_min, T r, T mu, T mu_s, T nu) {
    const T H = hd_sqrt(Rt * Rt - R0 * R0);
    r = hd_clamp(r, R0, Rt);
    const T rho = hd_sqrt(r * r - R0 * R0);
    Grid4Coord<T> c;
    c.xr = rho / H;
    const T rmu = r * mu;
    const T disc = rmu * rmu - r * r + R0 * R0;
    c.ground = mu < T(0) && disc >= T(0) ? 1 : 0;
    if (c.ground) {
        const T d = -rmu - hd_sqrt(disc);
        const T dmin = r - R0, dmax = rho;
        c.xmu = dmax > dmin ? hd_clamp((d - dmin) / (dmax - dmin), T(0), T(1)) : T(0);
    } else {
        const T d = -rmu + hd_sqrt(disc + H * H);
        const T dmin = Rt - r, dmax = rho + H;
        c.xmu = hd_clamp((d - dmin) / (dmax - dmin), T(0), T(1));
    }
    const T dmin = Rt - R0, dmax = H;
    const T a = (distance_to_top(R0, mu_s, Rt) - dmin) / (dmax - dmin);
    const T A = (distance_to_top(R0, mu_s_min, Rt) - dmin) / (dmax - dmin);
    const T x = T(1) - a / A;
    c.xmus = hd_clamp((x > T(0) ? x : T(0)) / (T(1) + a), T(0), T(1));
    c.xnu = hd_clamp((nu + T(1)) * T(0.5), T(0), T(1));
    return c;
}

// Row-major index of a node: ((((ir·2 + half)·nmu + imu)·nmus + imus)·nnu + inu).
SKYBAKE_HD_INLINE int grid4_index(int nmu, int nmus, int nnu, int ir, int half, int imu, int imus, int inu) {
    return (((ir * 2 + half) * nmu + imu) * nmus + imus) * nnu + inu;
}

// The lower node and fraction of coordinate x on an axis of n nodes.
template <class T>
SKYBAKE_HD_INLINE int grid_axis(T x, int n, T& f) {
    T s = x * T(n - 1);
    s = s < T(0) ? T(0) : s;
    int i = int(s);
    i = i > n - 2 ? n - 2 : i;
    f = s - T(i);
    f = f > T(1) ? T(1) : f;
    return i;
}

// Quadrilinear look-up in a grid of `stride` values per node, value j of the node.
template <class T, class V>
SKYBAKE_HD_INLINE T grid4_lookup(const V* values, int stride, int j, int nr, int nmu, int nmus, int nnu,
                                 const Grid4Coord<T>& c) {
    T fr, fm, fs, fn;
    const int ir = grid_axis(c.xr, nr, fr), im = grid_axis(c.xmu, nmu, fm), is = grid_axis(c.xmus, nmus, fs),
              in = grid_axis(c.xnu, nnu, fn);
    T sum = T(0);
    for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b)
            for (int s = 0; s < 2; ++s)
                for (int n = 0; n < 2; ++n) {
                    const T w = (a ? fr : T(1) - fr) * (b ? fm : T(1) - fm) * (s ? fs : T(1) - fs) * (n ? fn : T(1) - fn);
                    const int idx = grid4_index(nmu, nmus, nnu, ir + a, c.ground, im + b, is + s, in + n);
                    sum += w * T(values[idx * stride + j]);
                }
    return sum;
}

// Orders ≥ 2 at a point inside the atmosphere (r ≤ Rt), per unit sun irradiance.
SKYBAKE_HD_INLINE glm::vec3 orders_lookup(const MultipleHD& m, float R0, float Rt, float r, float mu, float mu_s,
                                          float nu) {
    // grid4_lookup for the three channels at once (same weights, same order of sums).
    const Grid4Coord<float> c = grid4_coordinates(R0, Rt, m.mu_s_min, r, mu, mu_s, nu);
    float fr, fm, fs, fn;
    const int ir = grid_axis(c.xr, m.nr, fr), im = grid_axis(c.xmu, m.nmu, fm), is = grid_axis(c.xmus, m.nmus, fs),
              in = grid_axis(c.xnu, m.nnu, fn);
    glm::vec3 sum(0.0f);
    for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b)
            for (int s = 0; s < 2; ++s)
                for (int n = 0; n < 2; ++n) {
                    const float w = (a ? fr : 1.0f - fr) * (b ? fm : 1.0f - fm) * (s ? fs : 1.0f - fs) *
                                    (n ? fn : 1.0f - fn);
                    const float* v = m.orders + 3 * grid4_index(m.nmu, m.nmus, m.nnu, ir + a, c.ground, im + b, is + s,
                                                                in + n);
                    sum += w * glm::vec3(v[0], v[1], v[2]);
                }
    return sum;
}

// Bilinear look-up in an RGB table over altitude (uniform, ground to top) and
// sun cosine (uniform in [−1, 1]).
SKYBAKE_HD_INLINE glm::vec3 altitude_sun_lookup(const float* t, int nr, int nmus, float R0, float Rt, float h,
                                                float mu_s) {
    float fr, fs;
    const int i = grid_axis(hd_clamp(h / (Rt - R0), 0.0f, 1.0f), nr, fr);
    const int j = grid_axis(hd_clamp(0.5f * (mu_s + 1.0f), 0.0f, 1.0f), nmus, fs);
    glm::vec3 v(0.0f);
    for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b) {
            const float w = (a ? fr : 1.0f - fr) * (b ? fs : 1.0f - fs);
            const float* p = t + ((i + a) * nmus + (j + b)) * 3;
            v += w * glm::vec3(p[0], p[1], p[2]);
        }
    return v;
}

// Hillaire's ψms at altitude h (km) and sun cosine mu_s.
SKYBAKE_HD_INLINE glm::vec3 psi_lookup(const MultipleHD& m, float R0, float Rt, float h, float mu_s) {
    return altitude_sun_lookup(m.psi, m.psi_nr, m.psi_nmus, R0, Rt, h, mu_s);
}

// Sky irradiance on a horizontal surface at altitude h (km) with sun cosine mu_s.
SKYBAKE_HD_INLINE glm::vec3 sky_irradiance_lookup(const MultipleHD& m, float R0, float Rt, float h, float mu_s) {
    if (m.irradiance == nullptr)
        return glm::vec3(0.0f);
    return altitude_sun_lookup(m.irradiance, m.irr_nr, m.irr_nmus, R0, Rt, h, mu_s);
}

} // namespace skybake::sky
