// A brute-force Monte Carlo path tracer of the atmosphere: the ground truth
// of the multiple-scattering methods (see docs/sky.md, "Monte Carlo reference").
//
// Paths start at the observer and run backwards to the sun. Free flights use
// delta (Woodcock) tracking against a constant majorant; the first collision
// along the view ray is forced (its probability 1 − T is known exactly); each
// scattering event adds the sun by next-event estimation with the exact
// transmittance towards it; directions are drawn from the phase functions
// (one-sample mixture over components); the ground is Lambertian at the
// atmosphere's albedo. Russian roulette ends weak paths without bias.
//
// Orders: every scattering event, in the air or on the ground, is one order.
// The sun reflected by the ground the view ray meets is not sky light and is
// not counted (as in SkyModel). Results are per unit sun irradiance, 1/sr,
// each channel traced on its own.
//
// Next events: by default each scattering event adds the sun (next-event
// estimation). With NextEvent::SunlitAir it adds instead the light that
// arrives along the path's next direction after one more scattering in sunlit
// air (or one reflection of the sun on the ground at the ray's end), from a
// quadrature of the single scattering along that ray (graded Gauss–Legendre
// over its sunlit part, within 1.5e-4 of the exact one): the same expectation,
// but a shadowed point now sees the lit air beyond the terminator through
// every direction it samples, not only through the rare paths that collide
// there. In the planet's shadow the directions are drawn from a one-sample
// mixture of the phase functions and a band around the local horizon towards
// the sun, where the lit air lies at twilight; and in this mode half the
// first collisions are uniform along the view ray (at twilight its light is
// gathered high up).
// This is the reference for deep twilight and night (docs/sky.md, "At
// night"); each event costs a quadrature, so it is slower per path.
//
// Deterministic: path i of channel c draws from SplitMix64 seeded by (seed, c, i),
// and partial sums are added in a fixed order, whatever the thread count.
#pragma once

#include <cstdint>

#include <glm/vec3.hpp>

#include "skybake/sky.h"

namespace skybake {

enum class NextEvent {
    Sun,       // the sun at every scattering event
    SunlitAir, // the once-scattered light along the next direction (twilight and night)
};

struct PathTracerOptions {
    std::uint64_t paths = 1u << 16; // per channel, ≥ 2
    std::uint64_t seed = 1;
    int min_order = 1;              // count scattering orders min_order..max_order (1 ≤ min ≤ max)
    int max_order = 1 << 20;
    NextEvent next_event = NextEvent::Sun;
};

struct PathTracedRadiance {
    glm::dvec3 mean{0.0};
    glm::dvec3 standard_error{0.0}; // of the mean, per channel
    std::uint64_t paths = 0;        // per channel
};

// The sky radiance an observer at radius_km (may be above the top) sees along
// the view given by the three cosines (as SkyModel::radiance_at_radius).
// The orders traced are the options' (the atmosphere's `scattering` fields
// are not read). Throws skybake::Error naming the field for bad options or
// cosines, and for a view ray whose optical depth is below 1e-6.
PathTracedRadiance path_trace_sky(const Atmosphere& atmosphere, double radius_km, double cos_view_zenith,
                                  double cos_view_sun, double cos_sun_zenith, const PathTracerOptions& options = {});

// The albedo problem: a semi-infinite plane-parallel slab of constant density
// and isotropic phase, with single-scattering albedo ϖ, lit by a parallel beam
// of unit irradiance (normal to the beam) from direction cosine mu_sun. The
// radiance it reflects towards direction cosine mu_view, all orders, is
// Chandrasekhar's (ϖ/4π) μ0/(μ+μ0) H(μ) H(μ0): the path tracer's own test.
struct SlabMedium {
    double single_scattering_albedo = 0.9; // ϖ in (0, 1]
};
// The result is the same in every channel.
PathTracedRadiance path_trace_slab_reflection(const SlabMedium& slab, double mu_view, double mu_sun,
                                              const PathTracerOptions& options = {});

} // namespace skybake
