// Real orthonormal spherical harmonics, evaluated from Cartesian coordinates
// with the normalised associated-Legendre recurrence (e.g. Schaeffer 2013,
// "Efficient spherical harmonic transforms aimed at pseudospectral numerical
// simulations", eq. 2-4) and (x + iy)^m for the azimuthal factors, so that the
// whole evaluation is polynomial in x, y, z: no trigonometry, no pole
// singularity, and it works with float, double or dual numbers alike.
//
// Convention (skybake/sh.h): no Condon–Shortley phase, Y_1,-1 ∝ y, Y_10 ∝ z,
// Y_11 ∝ x; index l² + l + m.
#pragma once

#include <cmath>

#include "core/hd.h"

namespace skybake::sphere {

// Recurrence factors a_lm, b_lm of the loop below, stored at 2·(l² + l + m) and +1
// for 0 ≤ m ≤ l − 2; sh_recurrence_table() in sh.cpp fills them. Passing a table
// saves two square roots per coefficient; nullptr computes them on the fly.
SKYBAKE_HD_INLINE int sh_recurrence_index(int l, int m) { return 2 * (l * l + l + m); }

// All Y_lm(x, y, z) for l ≤ lmax into out[(lmax+1)²]. (x, y, z): unit vector.
// T: float, double, or any type with +, −, × by T and by double.
template <class T>
SKYBAKE_HD_INLINE void sh_eval_hd(int lmax, T x, T y, T z, T* out, const double* table = nullptr) {
    using std::sqrt;
    // Q̄_m^m: normalised P_m^m / sin^m θ, Q̄_0^0 = 1/√(4π).
    double pmm = 0.28209479177387814; // 1/(2√π)
    T c = T(1.0), s = T(0.0);         // cos(mφ) sin^m θ, sin(mφ) sin^m θ
    for (int m = 0; m <= lmax; ++m) {
        if (m > 0) {
            pmm *= sqrt((2.0 * m + 1.0) / (2.0 * m));
            const T c_next = x * c - y * s;
            s = x * s + y * c;
            c = c_next;
        }
        // Band l = m, then l = m + 1, then the three-term recurrence in l.
        T q_lm2 = T(0.0);
        T q_lm1 = T(pmm);
        const double sqrt2 = m == 0 ? 1.0 : 1.4142135623730951;
        for (int l = m; l <= lmax; ++l) {
            T q;
            if (l == m) {
                q = q_lm1;
            } else if (l == m + 1) {
                q = z * q_lm1 * sqrt(2.0 * m + 3.0);
                q_lm2 = q_lm1;
                q_lm1 = q;
            } else {
                double a, b;
                if (table) {
                    a = table[sh_recurrence_index(l, m)];
                    b = table[sh_recurrence_index(l, m) + 1];
                } else {
                    const double ll = double(l) * l, mm = double(m) * m, l1 = double(l - 1);
                    a = sqrt((4.0 * ll - 1.0) / (ll - mm));
                    b = sqrt((l1 * l1 - mm) / (4.0 * l1 * l1 - 1.0));
                }
                q = (z * q_lm1 - q_lm2 * b) * a;
                q_lm2 = q_lm1;
                q_lm1 = q;
            }
            const int centre = l * l + l;
            if (m == 0) {
                out[centre] = q;
            } else {
                out[centre + m] = q * c * sqrt2;
                out[centre - m] = q * s * sqrt2;
            }
        }
    }
}

// Host copy of the recurrence factors up to kShMaxL (sh.cpp); copy it to the GPU
// for kernels that evaluate high bands.
const double* sh_recurrence_table();

} // namespace skybake::sphere
