// Hillaire's multiple-scattering table and the sky-irradiance table (see
// multiple_scattering_lut.cpp and sky_irradiance.cpp).
#pragma once

#include <vector>

#include "skybake/sky.h"
#include "sky/sky_hd.h"

namespace skybake {
class Progress;
}

namespace skybake::sky {

// Hillaire 2020's ψms over resolution.psi_r altitudes × resolution.psi_mu_s
// sun cosines (the layout of MultipleHD::psi), RGB floats, per unit sun irradiance.
// progress (may be null) advances once per node.
std::vector<float> hillaire_psi_table(const Atmosphere& atmosphere, const MultipleScatteringResolution& resolution,
                                      Progress* progress = nullptr);

// Irradiance of the scattered sky light on a horizontal surface, from the
// model's own radiance (sky_sum over `hd`, which must already hold its
// multiple-scattering tables), over resolution.irradiance_r ×
// resolution.irradiance_mu_s (the layout of MultipleHD::irradiance). progress
// (may be null) advances once per node.
std::vector<float> sky_irradiance_table(const AtmosphereHD& hd, const MultipleScatteringResolution& resolution,
                                        int steps, int spacing, Progress* progress = nullptr);

} // namespace skybake::sky
