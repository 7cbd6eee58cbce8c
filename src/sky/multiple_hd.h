// The coordinates of the multiple-scattering grids in float (the run-time
// look-ups of sky/sky_shared.h) and in double (the precomputation in
// scattering_orders.cpp): sky/grid4_shared.h, written once in the common
// subset of C++ and GLSL, included here for each type.
#pragma once

#include <cmath>

#include "core/hd.h"
#include "core/shared_source.h"

namespace skybake::sky {

#define Real float
#define SB_REAL_SQRT sqrtf
#define SB_REAL_LOG logf
#define SB_REAL_EXP expf
#include "sky/grid4_shared.h"
#undef Real
#undef SB_REAL_SQRT
#undef SB_REAL_LOG
#undef SB_REAL_EXP
#define Real double
#define SB_REAL_SQRT sqrt
#define SB_REAL_LOG log
#define SB_REAL_EXP exp
#include "sky/grid4_shared.h"
#undef Real
#undef SB_REAL_SQRT
#undef SB_REAL_LOG
#undef SB_REAL_EXP

// The unit-range coordinates of a point of the 4D grid (grid4_coordinates).
template <class T>
struct Grid4Coord {
    T xr, xmu, xmus, xnu;
    int ground; // 1: the ray meets the ground (the lower half of the μ axis)
};

template <class T>
SKYBAKE_HD_INLINE Grid4Coord<T> grid4_coordinates(T R0, T Rt, T mu_s_min, T r, T mu, T mu_s, T nu) {
    Grid4Coord<T> c;
    grid4_coordinates(R0, Rt, mu_s_min, r, mu, mu_s, nu, c.xr, c.xmu, c.xmus, c.xnu, c.ground);
    return c;
}

} // namespace skybake::sky
