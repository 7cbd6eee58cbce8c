// Ivanic J., Ruedenberg K. Rotation matrices for real spherical harmonics.
// Direct determination by recursion. J. Phys. Chem. 100(15), 1996, 6342-6347;
// Additions and corrections, J. Phys. Chem. A 102(45), 1998, 9099-9100.
//
// Band 1 of the real SH (Y_1,-1, Y_10, Y_11) ∝ (y, z, x), so its rotation matrix
// is R with rows and columns permuted to (y, z, x); band l follows from bands 1
// and l − 1 by the recurrence of table 2 of the 1996 paper (u, v, w and the
// functions P, U, V, W), with the 1998 correction of the coefficients.
#include <cassert>
#include <cmath>

#include <fmt/format.h>

#include "skybake/error.h"
#include "skybake/sh.h"

namespace skybake {

namespace {

struct Band {
    int l;
    const std::vector<double>* m;
    double operator()(int row, int col) const { return (*m)[std::size_t((row + l) * (2 * l + 1) + (col + l))]; }
};

// P(i, l, a, b) of Ivanic & Ruedenberg, with r = band 1 and prev = band l − 1.
double P(int i, int l, int a, int b, const Band& r, const Band& prev) {
    if (b == l)
        return r(i, 1) * prev(a, l - 1) - r(i, -1) * prev(a, -l + 1);
    if (b == -l)
        return r(i, 1) * prev(a, -l + 1) + r(i, -1) * prev(a, l - 1);
    return r(i, 0) * prev(a, b);
}

} // namespace

ShRotation::ShRotation(int lmax, const glm::dmat3& rot) : lmax_(lmax) {
    if (lmax < 0 || lmax > kShMaxL)
        throw Error(fmt::format("spherical-harmonic band limit {} is out of range 0 to {}", lmax, kShMaxL), "lmax");
    bands_.resize(std::size_t(lmax + 1));
    bands_[0] = {1.0};
    if (lmax == 0)
        return;
    // Band 1: M[m][n] = R[perm(m)][perm(n)], perm(−1, 0, 1) = (y, z, x) = (1, 2, 0).
    // glm is column-major: rot[col][row].
    static constexpr int kPerm[3] = {1, 2, 0};
    bands_[1].resize(9);
    for (int m = -1; m <= 1; ++m)
        for (int n = -1; n <= 1; ++n)
            bands_[1][std::size_t((m + 1) * 3 + (n + 1))] = rot[kPerm[n + 1]][kPerm[m + 1]];
    const Band r{1, &bands_[1]};
    for (int l = 2; l <= lmax; ++l) {
        const Band prev{l - 1, &bands_[std::size_t(l - 1)]};
        std::vector<double>& band = bands_[std::size_t(l)];
        band.assign(std::size_t((2 * l + 1) * (2 * l + 1)), 0.0);
        for (int m = -l; m <= l; ++m) {
            for (int n = -l; n <= l; ++n) {
                const int d = m == 0 ? 1 : 0;
                const int am = std::abs(m);
                const double denom = std::abs(n) == l ? double(2 * l) * (2 * l - 1) : double(l + n) * (l - n);
                const double u = std::sqrt(double(l + m) * (l - m) / denom);
                const double v = 0.5 * std::sqrt((1.0 + d) * (l + am - 1.0) * (l + am) / denom) * (1.0 - 2.0 * d);
                const double w = -0.5 * std::sqrt((l - am - 1.0) * (l - am) / denom) * (1.0 - d);
                double value = 0.0;
                if (u != 0.0)
                    value += u * P(0, l, m, n, r, prev);
                if (v != 0.0) {
                    double V;
                    if (m == 0)
                        V = P(1, l, 1, n, r, prev) + P(-1, l, -1, n, r, prev);
                    else if (m > 0)
                        V = P(1, l, m - 1, n, r, prev) * std::sqrt(m == 1 ? 2.0 : 1.0) -
                            P(-1, l, -m + 1, n, r, prev) * (m == 1 ? 0.0 : 1.0);
                    else
                        V = P(1, l, m + 1, n, r, prev) * (m == -1 ? 0.0 : 1.0) +
                            P(-1, l, -m - 1, n, r, prev) * std::sqrt(m == -1 ? 2.0 : 1.0);
                    value += v * V;
                }
                if (w != 0.0) {
                    double W;
                    if (m > 0)
                        W = P(1, l, m + 1, n, r, prev) + P(-1, l, -m - 1, n, r, prev);
                    else
                        W = P(1, l, m - 1, n, r, prev) - P(-1, l, -m + 1, n, r, prev);
                    value += w * W;
                }
                band[std::size_t((m + l) * (2 * l + 1) + (n + l))] = value;
            }
        }
    }
}

double ShRotation::element(int l, int m, int n) const {
    assert(l >= 0 && l <= lmax_ && std::abs(m) <= l && std::abs(n) <= l);
    return bands_[std::size_t(l)][std::size_t((m + l) * (2 * l + 1) + (n + l))];
}

void ShRotation::apply(const double* in, double* out) const {
    for (int l = 0; l <= lmax_; ++l) {
        const std::vector<double>& band = bands_[std::size_t(l)];
        const int size = 2 * l + 1, base = l * l;
        for (int i = 0; i < size; ++i) {
            double sum = 0.0;
            for (int j = 0; j < size; ++j)
                sum += band[std::size_t(i * size + j)] * in[base + j];
            out[base + i] = sum;
        }
    }
}

std::vector<double> ShRotation::apply(const std::vector<double>& coeffs) const {
    if (coeffs.size() < std::size_t(sh_count(lmax_)))
        throw Error(fmt::format("rotating band {} needs {} coefficients, got {}", lmax_, sh_count(lmax_), coeffs.size()),
                    "ShRotation");
    std::vector<double> out(std::size_t(sh_count(lmax_)));
    apply(coeffs.data(), out.data());
    return out;
}

std::vector<glm::dvec3> ShRotation::apply(const std::vector<glm::dvec3>& coeffs) const {
    if (coeffs.size() < std::size_t(sh_count(lmax_)))
        throw Error(fmt::format("rotating band {} needs {} coefficients, got {}", lmax_, sh_count(lmax_), coeffs.size()),
                    "ShRotation");
    const std::size_t count = std::size_t(sh_count(lmax_));
    std::vector<glm::dvec3> out(count);
    std::vector<double> in(count), res(count);
    for (int c = 0; c < 3; ++c) {
        for (std::size_t i = 0; i < count; ++i)
            in[i] = coeffs[i][c];
        apply(in.data(), res.data());
        for (std::size_t i = 0; i < count; ++i)
            out[i][c] = res[i];
    }
    return out;
}

std::vector<double> sh_rotate(const std::vector<double>& coeffs, int lmax, const glm::dmat3& rotation) {
    return ShRotation(lmax, rotation).apply(coeffs);
}

} // namespace skybake
