// skybake/sh.h: real orthonormal spherical harmonics.
//
// [SECTION] Convention and indexing
// [SECTION] Evaluation
// [SECTION] Projection
// [SECTION] Rotation
// [SECTION] Zonal convolution (clamped cosine, Phong lobe)
//
// The per-direction evaluation is also available to CUDA kernels, as
// sphere::sh_eval_hd() in src/sphere/sh_eval.h (same values, float or double).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "skybake/image.h"
#include "skybake/sphere.h"

namespace skybake {

// [SECTION] Convention and indexing -------------------------------------------------
//
// Real SH, orthonormal over the sphere (∫ Y_lm Y_l'm' dω = δ), without the
// Condon–Shortley phase, in a right-handed frame with θ measured from +z:
//   Y_00 = 1/(2√π)
//   Y_1,-1 = √(3/4π) y,   Y_10 = √(3/4π) z,   Y_11 = √(3/4π) x
//   Y_2,-2 = ½√(15/π) xy, Y_2,-1 = ½√(15/π) yz, Y_20 = ¼√(5/π)(3z² − 1),
//   Y_21 = ½√(15/π) xz,   Y_22 = ¼√(15/π)(x² − y²)
// This is the table of Ramamoorthi & Hanrahan 2001 ("An efficient
// representation for irradiance environment maps", eq. 3): every Y_lm
// positive where its polynomial is, no (−1)^m. Sloan's "Stupid spherical
// harmonics tricks" (2008) and D3DX (D3DXSHEvalDirection) use the
// Condon–Shortley phase instead: their Y_lm is (−1)^m times ours, so the
// coefficients with odd |m| (Y_1,±1, Y_2,±1, Y_3,±1, Y_3,±3, ...) change sign
// and the others are equal. skybake computes in its own convention and
// converts at its edges (ShConvention below: light files, shader exports).
//
// "lmax" is the highest band l; a band-limited function has sh_count(lmax) =
// (lmax + 1)² coefficients, stored at sh_index(l, m) = l² + l + m. lmax ≤ 200.
constexpr int kShMaxL = 200;
constexpr int sh_count(int lmax) { return (lmax + 1) * (lmax + 1); }
constexpr int sh_index(int l, int m) { return l * l + l + m; }

// The sign convention of a set of coefficients outside skybake.
enum class ShConvention : int {
    Skybake = 0,        // the table above (Ramamoorthi & Hanrahan 2001), no (−1)^m
    CondonShortley = 1, // (−1)^m Y_lm: Sloan 2008, D3DX
};
// "skybake", "condon-shortley".
const char* sh_convention_name(ShConvention convention);
// Throws skybake::Error (where: "sh_convention") listing the names.
ShConvention parse_sh_convention(const std::string& text);
// The factor between the two conventions for index sh_index(l, m): −1 for
// odd |m| under CondonShortley, else 1. Converting is its own inverse.
constexpr double sh_convention_sign(int m, ShConvention convention) {
    return convention == ShConvention::CondonShortley && (m % 2 != 0) ? -1.0 : 1.0;
}
// Multiplies each of the sh_count(lmax) coefficients (index order) by its
// sh_convention_sign(): skybake's coefficients into `convention`, or back.
template <class T>
void convert_sh_convention(std::vector<T>& coeffs, int lmax, ShConvention convention) {
    for (int l = 0; l <= lmax; ++l)
        for (int m = -l; m <= l; ++m)
            if (const std::size_t i = std::size_t(sh_index(l, m)); i < coeffs.size() && sh_convention_sign(m, convention) < 0)
                coeffs[i] = -coeffs[i];
}

// [SECTION] Evaluation -----------------------------------------------------------------

// All Y_lm(dir) for l ≤ lmax into out[sh_count(lmax)]. dir: unit vector.
void sh_eval(int lmax, const glm::dvec3& dir, double* out);
std::vector<double> sh_eval(int lmax, const glm::dvec3& dir);
// Σ_lm c_lm Y_lm(dir); coeffs has sh_count(lmax) entries.
double sh_evaluate(const std::vector<double>& coeffs, int lmax, const glm::dvec3& dir);
glm::dvec3 sh_evaluate(const std::vector<glm::dvec3>& coeffs, int lmax, const glm::dvec3& dir);

// [SECTION] Projection -----------------------------------------------------------------
//
// c_lm = ∫ f Y_lm dω, computed as 4π Σ_k w_k f(x_k) Y_lm(x_k) with a rule of the
// normalised measure (not a Phong rule). Exact for a band-limited f when the
// rule's precision is ≥ 2 lmax (l_f + lmax in general). A good default is
// "lebedev:5810" (precision 131).
std::vector<double> sh_project(const std::function<double(const glm::dvec3&)>& f, int lmax,
                               const SphereRule& rule);

// Equirectangular (latitude–longitude) environment map, linear RGB.
// Column u ∈ [0, width) covers the azimuth φ = atan2(y, x) ∈ [0, 2π) from left to
// right; row v ∈ [0, height) covers θ = acos(z) from +z (top row) to −z. Pixel
// centres sit at ((i + ½)/width, (j + ½)/height). Lookups are bilinear, wrapping
// in φ and clamping in θ (seed 002: "read with bilinear interpolation").
glm::dvec3 sample_equirect(const Image& env, const glm::dvec3& dir);
// Per-channel SH coefficients of an environment map (sampled with sample_equirect
// at the rule's points). Throws skybake::Error on an empty image.
std::vector<glm::dvec3> sh_project_equirect(const Image& env, int lmax, const SphereRule& rule);

// [SECTION] Rotation ---------------------------------------------------------------------
//
// Ivanic & Ruedenberg 1996 (with the 1998 erratum): a rotation of the sphere acts
// on each band l by a (2l+1)×(2l+1) orthogonal matrix, built by recurrence from
// band 1. For g(x) = f(Rᵀ x) (f turned by R), g_lm = Σ_n M^l_mn f_ln.
class ShRotation {
public:
    // rotation: proper rotation matrix (orthonormal, det +1), any frame.
    ShRotation(int lmax, const glm::dmat3& rotation);
    int lmax() const { return lmax_; }
    // Element M^l_mn, |m|, |n| ≤ l ≤ lmax.
    double element(int l, int m, int n) const;
    // out = M in; in and out hold sh_count(lmax) values and may not alias.
    void apply(const double* in, double* out) const;
    std::vector<double> apply(const std::vector<double>& coeffs) const;
    std::vector<glm::dvec3> apply(const std::vector<glm::dvec3>& coeffs) const;

private:
    int lmax_;
    std::vector<std::vector<double>> bands_; // band l: row-major (2l+1)²
};

// Coefficients of f turned by rotation: g(x) = f(rotationᵀ x).
std::vector<double> sh_rotate(const std::vector<double>& coeffs, int lmax, const glm::dmat3& rotation);

// [SECTION] Zonal convolution --------------------------------------------------------------
//
// For a kernel k(t) of t = cos of the angle to an axis, the convolution
//     (k ⋆ f)(n) = ∫ k(n·x) f(x) dω
// has coefficients (k ⋆ f)_lm = k̂_l f_lm, with the Funk–Hecke factors
//     k̂_l = 2π ∫_{-1}^{1} k(t) P_l(t) dt.
// With k = max(t, 0) this turns radiance into irradiance (Ramamoorthi & Hanrahan
// 2001: Â_0 = π, Â_1 = 2π/3, Â_2 = π/4, Â_3 = 0, Â_4 = −π/24).

// Â_l for the clamped cosine max(t, 0).
double clamped_cosine_zonal(int l);
// k̂_l for the Phong lobe max(t, 0)^a (not normalised; multiply by 2(a+1)/(4π)
// for the normalised lobe ρ_a of skybake/sphere.h). a ≥ 0.
double phong_lobe_zonal(int l, double exponent_a);
// out_lm = kernel[l] · coeffs_lm; kernel has lmax + 1 entries.
std::vector<double> sh_convolve_zonal(const std::vector<double>& coeffs, int lmax, const std::vector<double>& kernel);

} // namespace skybake
