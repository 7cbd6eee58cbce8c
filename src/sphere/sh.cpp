// Real spherical harmonics: evaluation (sh_eval.h), projection of functions and
// of equirectangular environment maps, and zonal convolution.
//
// Zonal factors: Funk–Hecke theorem; for the clamped cosine, Ramamoorthi R.,
// Hanrahan P. An efficient representation for irradiance environment maps.
// SIGGRAPH 2001, eq. 8-9. The power-cosine integral is Gradshteyn & Ryzhik
// 7.126.2 (with ν = l, μ = a):
//   ∫_0^1 t^a P_l(t) dt = √π 2^(−a−1) Γ(a + 1) / (Γ(1 + a/2 − l/2) Γ(a/2 + l/2 + 3/2)).
#include <algorithm>
#include <cassert>
#include <cmath>

#include <fmt/format.h>

#include "skybake/error.h"
#include "skybake/names.h"
#include "skybake/sh.h"
#include "sphere/sh_eval.h"

namespace skybake {

namespace {

void check_lmax(int lmax) {
    if (lmax < 0 || lmax > kShMaxL)
        throw Error(fmt::format("spherical-harmonic band limit {} is out of range 0 to {}", lmax, kShMaxL), "lmax");
}

// 1/Γ(z), 0 at the poles z = 0, −1, −2, ...; returned as (log|1/Γ|, sign).
bool reciprocal_gamma_is_zero(double z) { return z <= 0.0 && z == std::floor(z); }
double gamma_sign(double z) {
    if (z > 0.0)
        return 1.0;
    const double k = std::ceil(-z); // poles passed
    return std::fmod(k, 2.0) == 1.0 ? -1.0 : 1.0;
}

} // namespace

namespace sphere {

const double* sh_recurrence_table() {
    static const std::vector<double> table = [] {
        std::vector<double> t(std::size_t(2 * sh_count(kShMaxL)), 0.0);
        for (int l = 2; l <= kShMaxL; ++l)
            for (int m = 0; m <= l - 2; ++m) {
                const double ll = double(l) * l, mm = double(m) * m, l1 = double(l - 1);
                t[std::size_t(sh_recurrence_index(l, m))] = std::sqrt((4.0 * ll - 1.0) / (ll - mm));
                t[std::size_t(sh_recurrence_index(l, m) + 1)] = std::sqrt((l1 * l1 - mm) / (4.0 * l1 * l1 - 1.0));
            }
        return t;
    }();
    return table.data();
}

} // namespace sphere

void sh_eval(int lmax, const glm::dvec3& dir, double* out) {
    assert(lmax >= 0 && lmax <= kShMaxL);
    static const double* table = sphere::sh_recurrence_table();
    sphere::sh_eval_hd<double>(lmax, dir.x, dir.y, dir.z, out, table);
}

std::vector<double> sh_eval(int lmax, const glm::dvec3& dir) {
    check_lmax(lmax);
    std::vector<double> out(std::size_t(sh_count(lmax)));
    sh_eval(lmax, dir, out.data());
    return out;
}

double sh_evaluate(const std::vector<double>& coeffs, int lmax, const glm::dvec3& dir) {
    check_lmax(lmax);
    assert(coeffs.size() >= std::size_t(sh_count(lmax)));
    thread_local std::vector<double> y;
    y.resize(std::size_t(sh_count(lmax)));
    sh_eval(lmax, dir, y.data());
    double sum = 0.0;
    for (std::size_t i = 0; i < y.size(); ++i)
        sum += coeffs[i] * y[i];
    return sum;
}

glm::dvec3 sh_evaluate(const std::vector<glm::dvec3>& coeffs, int lmax, const glm::dvec3& dir) {
    check_lmax(lmax);
    assert(coeffs.size() >= std::size_t(sh_count(lmax)));
    thread_local std::vector<double> y;
    y.resize(std::size_t(sh_count(lmax)));
    sh_eval(lmax, dir, y.data());
    glm::dvec3 sum(0.0);
    for (std::size_t i = 0; i < y.size(); ++i)
        sum += coeffs[i] * y[i];
    return sum;
}

std::vector<double> sh_project(const std::function<double(const glm::dvec3&)>& f, int lmax, const SphereRule& rule) {
    check_lmax(lmax);
    const std::size_t count = std::size_t(sh_count(lmax));
    std::vector<double> coeffs(count, 0.0), y(count);
    const double four_pi = 12.566370614359172;
    for (std::size_t k = 0; k < rule.points.size(); ++k) {
        const double fw = four_pi * rule.weights[k] * f(rule.points[k]);
        sh_eval(lmax, rule.points[k], y.data());
        for (std::size_t i = 0; i < count; ++i)
            coeffs[i] += fw * y[i];
    }
    return coeffs;
}

glm::dvec3 sample_equirect(const Image& env, const glm::dvec3& dir) {
    assert(env.width > 0 && env.height > 0);
    const double pi = 3.141592653589793;
    double phi = std::atan2(dir.y, dir.x);
    if (phi < 0.0)
        phi += 2.0 * pi;
    const double theta = std::acos(std::clamp(dir.z, -1.0, 1.0));
    // Continuous pixel coordinates with centres at integers.
    const double u = phi / (2.0 * pi) * env.width - 0.5;
    const double v = theta / pi * env.height - 0.5;
    const double u0f = std::floor(u), v0f = std::floor(v);
    const double fu = u - u0f, fv = v - v0f;
    auto wrap = [&](long long i) { return int(((i % env.width) + env.width) % env.width); };
    auto clampy = [&](long long j) { return int(std::clamp<long long>(j, 0, env.height - 1)); };
    const int x0 = wrap((long long)u0f), x1 = wrap((long long)u0f + 1);
    const int y0 = clampy((long long)v0f), y1 = clampy((long long)v0f + 1);
    auto px = [&](int x, int y) {
        const float* p = env.pixel(x, y);
        return glm::dvec3(p[0], p[1], p[2]);
    };
    return (1 - fv) * ((1 - fu) * px(x0, y0) + fu * px(x1, y0)) + fv * ((1 - fu) * px(x0, y1) + fu * px(x1, y1));
}

std::vector<glm::dvec3> sh_project_equirect(const Image& env, int lmax, const SphereRule& rule) {
    check_lmax(lmax);
    if (env.width <= 0 || env.height <= 0 || env.rgb.size() != std::size_t(env.width) * std::size_t(env.height) * 3)
        throw Error("the environment map is empty or its pixel buffer does not match its size", "environment map");
    const std::size_t count = std::size_t(sh_count(lmax));
    std::vector<glm::dvec3> coeffs(count, glm::dvec3(0.0));
    std::vector<double> y(count);
    const double four_pi = 12.566370614359172;
    for (std::size_t k = 0; k < rule.points.size(); ++k) {
        const glm::dvec3 radiance = four_pi * rule.weights[k] * sample_equirect(env, rule.points[k]);
        sh_eval(lmax, rule.points[k], y.data());
        for (std::size_t i = 0; i < count; ++i)
            coeffs[i] += radiance * y[i];
    }
    return coeffs;
}

double phong_lobe_zonal(int l, double a) {
    if (l < 0)
        throw Error(fmt::format("band {} is negative", l), "l");
    if (!(a >= 0.0) || !std::isfinite(a))
        throw Error(fmt::format("the Phong exponent must be a finite number ≥ 0, got {}", a), "a");
    const double z1 = 1.0 + 0.5 * a - 0.5 * l;
    const double z2 = 0.5 * a + 0.5 * l + 1.5;
    if (reciprocal_gamma_is_zero(z1))
        return 0.0;
    const double pi = 3.141592653589793;
    const double log_value =
        0.5 * std::log(pi) - (a + 1.0) * std::log(2.0) + std::lgamma(a + 1.0) - std::lgamma(z1) - std::lgamma(z2);
    return 2.0 * pi * gamma_sign(z1) * std::exp(log_value);
}

double clamped_cosine_zonal(int l) { return phong_lobe_zonal(l, 1.0); }

std::vector<double> sh_convolve_zonal(const std::vector<double>& coeffs, int lmax, const std::vector<double>& kernel) {
    check_lmax(lmax);
    if (coeffs.size() < std::size_t(sh_count(lmax)) || kernel.size() < std::size_t(lmax + 1))
        throw Error(fmt::format("zonal convolution to band {} needs {} coefficients and {} kernel factors, got {} and {}",
                                lmax, sh_count(lmax), lmax + 1, coeffs.size(), kernel.size()),
                    "sh_convolve_zonal");
    std::vector<double> out(std::size_t(sh_count(lmax)));
    for (int l = 0; l <= lmax; ++l)
        for (int m = -l; m <= l; ++m)
            out[std::size_t(sh_index(l, m))] = kernel[std::size_t(l)] * coeffs[std::size_t(sh_index(l, m))];
    return out;
}

namespace {
constexpr NamedValue<ShConvention> kShConventionNames[] = {
    {ShConvention::Skybake, "skybake", "no (-1)^m: Ramamoorthi & Hanrahan 2001"},
    {ShConvention::CondonShortley, "condon-shortley", "(-1)^m: Sloan 2008, D3DX"},
};
} // namespace

const char* sh_convention_name(ShConvention convention) { return name_of(kShConventionNames, convention); }

ShConvention parse_sh_convention(const std::string& text) {
    return parse_name(kShConventionNames, text, "SH convention", "sh_convention");
}

} // namespace skybake
