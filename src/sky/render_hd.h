// Per-pixel camera and per-ray shading of sky images, shared by the CPU
// renderer and a CUDA one, and by the planet renderer's shaders: the functions
// are in sky/shade_shared.h, written once in the common subset of C++ and
// GLSL; this header is their C++ side.
#pragma once

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "sky/sky_hd.h"

namespace skybake::sky {

// The sky function of the *_approximate shading: a functor argument
// sky_fn(cos α0, cos β0, cos θ0, ρ0) -> radiance.
#define SB_SKY_TEMPLATE template <class SkyFunction>
#define SB_SKY_PARAM const SkyFunction& sky_fn
#define SB_SKY_ARG sky_fn
#define SB_SKY(cv, cvs, cs, rho) sky_fn(cv, cvs, cs, rho)

#include "sky/shade_shared.h"

} // namespace skybake::sky
