// The part of a view ray in the planet's shadow: the umbra of a sphere of
// radius R lit by a parallel sun is the half-cylinder behind it,
//     { p : p·s < 0 and |p − (p·s) s|² < R² }
// (s the unit direction towards the sun, the planet's centre at the origin).
// Along p(t) = o + t v from an observer at radius r (o = r U), with the
// cosines of the sky's samples (μ = V·U, ν = V·L, μs = U·L):
//     p·s  = r μs + t ν,
//     d²(t) = |p|² − (p·s)² = (1 − ν²) t² + 2 r (μ − μs ν) t + r² (1 − μs²),
// so the shadow is where a linear function is negative and a quadratic is
// below R²: one interval of t (the intersection of two convex sets). At
// twilight only the rest of the ray is lit; this gives where the ray enters
// and leaves the shadow in a few operations (seed 000's sum marches the ray
// and tests each step). SKYBAKE_HD: for CUDA kernels as well.
#ifndef SKYBAKE_SKY_PLANET_SHADOW_HD_H
#define SKYBAKE_SKY_PLANET_SHADOW_HD_H

#include <cmath>

#include "core/hd.h"

namespace skybake::sky {

// [t0, t1] with 0 ≤ t0 ≤ t1 (t1 may be +∞) where the ray is in shadow, or
// t0 > t1 (empty). r > 0 the observer's distance from the planet's centre,
// R the planet's radius (both km), mu, nu, mu_s the cosines above.
template <class Real>
struct ShadowInterval {
    Real t0, t1;
};

// Narrows [lo, hi] to where c + k t < 0; false where that is nowhere.
template <class Real>
SKYBAKE_HD_INLINE bool narrow_to_negative(Real c, Real k, Real& lo, Real& hi) {
    if (k > Real(0))
        hi = fmin(hi, -c / k);
    else if (k < Real(0))
        lo = fmax(lo, -c / k);
    else
        return c < Real(0);
    return true;
}

template <class Real>
SKYBAKE_HD_INLINE ShadowInterval<Real> planet_shadow_interval(Real r, Real R, Real mu, Real nu, Real mu_s) {
    Real lo = Real(0), hi = Real(INFINITY);
    // Behind the terminator plane: r μs + t ν < 0.
    if (!narrow_to_negative(r * mu_s, nu, lo, hi))
        return {Real(1), Real(0)};
    // Inside the cylinder: A t² + B t + C < 0.
    const Real A = Real(1) - nu * nu, B = Real(2) * r * (mu - mu_s * nu), C = r * r * (Real(1) - mu_s * mu_s) - R * R;
    if (A <= Real(1e-12) * (r * r) / (R * R + r * r)) {
        // Along the sun: the distance to the axis is constant to first order.
        if (!narrow_to_negative(C, B, lo, hi))
            return {Real(1), Real(0)};
    } else {
        const Real D = B * B - Real(4) * A * C;
        if (!(D > Real(0)))
            return {Real(1), Real(0)};
        // The stable pair of roots (Numerical Recipes, 5.6).
        const Real q = -Real(0.5) * (B + copysign(sqrt(D), B));
        Real ta = q / A, tb = q != Real(0) ? C / q : -ta;
        if (ta > tb) {
            const Real t = ta;
            ta = tb;
            tb = t;
        }
        lo = fmax(lo, ta);
        hi = fmin(hi, tb);
    }
    return {lo, hi};
}

} // namespace skybake::sky

#endif
