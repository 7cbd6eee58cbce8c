// The coordinates of the multiple-scattering grids, written once in the
// common subset of C++ and GLSL (core/shared_source.h) on a type `Real`:
// C++ includes this file twice, with Real = float (the run-time look-ups of
// sky_shared.h) and Real = double (the precomputation in scattering_orders.cpp),
// and the planet renderer's shaders once with Real = float. The includer
// defines Real and SB_REAL_SQRT, SB_REAL_LOG, SB_REAL_EXP (sqrtf, logf, expf for
// float; sqrt, log, exp for double and GLSL).
// No include guard, on purpose; what does not depend on Real is guarded.
//
// Bruneton E. A Qualitative and Quantitative Evaluation of 8 Clear Sky
// Models. IEEE TVCG 2017, and its reference implementation "Precomputed
// Atmospheric Scattering" (section "Texture coordinates"): the 4D grid over
// (r, μ, μs, ν), with μ split at the horizon so that rays that meet the
// ground and rays that do not are never interpolated together.
//
// Notation: r radius (km), μ cosine of the view direction to the local
// vertical, μs cosine of the sun direction to the local vertical, ν cosine of
// the view direction to the sun direction.

#ifndef SKYBAKE_SKY_GRID4_SHARED_ONCE
#define SKYBAKE_SKY_GRID4_SHARED_ONCE
// Row-major index of a node: ((((ir·2 + lower)·nmu + imu)·nmus + imus)·nnu + inu);
// lower = 1 for the half of the μ axis whose rays meet the ground.
SKYBAKE_HD_INLINE int grid4_index(int nmu, int nmus, int nnu, int ir, int lower, int imu, int imus, int inu) {
    return (((ir * 2 + lower) * nmu + imu) * nmus + imus) * nnu + inu;
}
#endif

SKYBAKE_HD_INLINE Real hd_sqrt(Real x) { return SB_REAL_SQRT(x > Real(0) ? x : Real(0)); }

SKYBAKE_HD_INLINE Real hd_clamp(Real x, Real lo, Real hi) { return x < lo ? lo : (x > hi ? hi : x); }

// Distance from radius r along a ray with cosine mu to the top Rt (r ≤ Rt).
SKYBAKE_HD_INLINE Real distance_to_top(Real r, Real mu, Real Rt) {
    return -r * mu + hd_sqrt(r * r * (mu * mu - Real(1)) + Rt * Rt);
}

// The lower node and fraction of coordinate x on an axis of n nodes.
SKYBAKE_HD_INLINE int grid_axis(Real x, int n, SB_OUT(Real) f) {
    Real s = x * Real(n - 1);
    s = s < Real(0) ? Real(0) : s;
    int i = int(s);
    i = i > n - 2 ? n - 2 : i;
    f = s - Real(i);
    f = f > Real(1) ? Real(1) : f;
    return i;
}

// Bruneton 2017's sun-cosine coordinate (x = 0 at mu_s_min, 1 at the zenith),
// denser near the horizon; constant below mu_s_min.
SKYBAKE_HD_INLINE Real grid4_mus_coordinate(Real R0, Real Rt, Real mu_s_min, Real mu_s) {
    Real H = hd_sqrt(Rt * Rt - R0 * R0);
    Real dmin = Rt - R0;
    Real dmax = H;
    Real a = (distance_to_top(R0, mu_s, Rt) - dmin) / (dmax - dmin);
    Real A = (distance_to_top(R0, mu_s_min, Rt) - dmin) / (dmax - dmin);
    Real x = Real(1) - a / A;
    return hd_clamp((x > Real(0) ? x : Real(0)) / (Real(1) + a), Real(0), Real(1));
}

// Bruneton 2017's mapping of a point to the unit-range coordinates of the 4D
// grid (x = 0..1 on each axis), without the texel-centre offsets. ground = 1:
// the ray meets the ground (the lower half of the μ axis).
SKYBAKE_HD_INLINE void grid4_coordinates(Real R0, Real Rt, Real mu_s_min, Real r, Real mu, Real mu_s, Real nu,
                                         SB_OUT(Real) xr, SB_OUT(Real) xmu, SB_OUT(Real) xmus, SB_OUT(Real) xnu,
                                         SB_OUT(int) ground) {
    Real H = hd_sqrt(Rt * Rt - R0 * R0);
    r = hd_clamp(r, R0, Rt);
    Real rho = hd_sqrt(r * r - R0 * R0);
    xr = rho / H;
    Real rmu = r * mu;
    Real disc = rmu * rmu - r * r + R0 * R0;
    ground = mu < Real(0) && disc >= Real(0) ? 1 : 0;
    if (ground == 1) {
        Real d = -rmu - hd_sqrt(disc);
        Real dmin = r - R0;
        Real dmax = rho;
        xmu = dmax > dmin ? hd_clamp((d - dmin) / (dmax - dmin), Real(0), Real(1)) : Real(0);
    } else {
        Real d = -rmu + hd_sqrt(disc + H * H);
        Real dmin = Rt - r;
        Real dmax = rho + H;
        xmu = hd_clamp((d - dmin) / (dmax - dmin), Real(0), Real(1));
    }
    xmus = grid4_mus_coordinate(R0, Rt, mu_s_min, mu_s);
    xnu = hd_clamp((nu + Real(1)) * Real(0.5), Real(0), Real(1));
}

// Whether the μs cell [is, is + 1] of an axis of nmus nodes lies where the sun
// is below the horizon (its upper node at μs ≤ 0). There the light falls by
// orders of magnitude from node to node, nearly exponentially, and the grids
// are interpolated geometrically along μs (grid4_mus_blend): linearly, the
// night sky would keep a fraction of the twilight's light between nodes.
// x_horizon: grid4_mus_coordinate of μs = 0 (a constant of the grid).
SKYBAKE_HD_INLINE int grid4_mus_cell_below_horizon(Real x_horizon, int nmus, int is) {
    return Real(is + 1) <= x_horizon * Real(nmus - 1) + Real(1e-3) ? 1 : 0;
}

// The value between the μs nodes' values a (lower) and b at fraction f:
// linear, or geometric in a cell below the horizon (values floored at 1e-30,
// below any light the grids hold; 0 where both are).
SKYBAKE_HD_INLINE Real grid4_mus_blend(Real a, Real b, Real f, int below_horizon) {
    if (below_horizon == 0)
        return a + f * (b - a);
    // At a node (the precomputation's own look-ups), no logarithms.
    if (f < Real(1e-6))
        return a;
    if (f > Real(1) - Real(1e-6))
        return b;
    if (!(a > Real(1e-30)) && !(b > Real(1e-30)))
        return Real(0); // no light at either node: none between them
    Real la = SB_REAL_LOG(a > Real(1e-30) ? a : Real(1e-30));
    Real lb = SB_REAL_LOG(b > Real(1e-30) ? b : Real(1e-30));
    return SB_REAL_EXP(la + f * (lb - la));
}
