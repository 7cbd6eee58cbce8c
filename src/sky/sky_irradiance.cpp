// Irradiance of the scattered sky light on a horizontal surface,
//   E(h, μs) = ∫_{2π} I(h, ω, μs) (ω·n) dω,
// from the model's own radiance I (single plus multiple scattering), by the
// midpoint product rule on the upper hemisphere. The surface colour and the
// rendered ground add (albedo/π) E to the direct sun (seed 000 section IV
// counts the sun only).
#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "core/parallel.h"
#include "core/progress.h"
#include "sky/multiple_scattering_lut.h"

namespace skybake::sky {

std::vector<float> sky_irradiance_table(const AtmosphereHD& hd, const MultipleScatteringResolution& res, int steps,
                                        int spacing, Progress* progress) {
    constexpr double kPi = 3.14159265358979323846;
    const int n = std::max(4, res.sphere / 2); // polar bands on the hemisphere
    const double dth = 0.5 * kPi / double(n), dph = kPi / double(n);
    std::vector<float> out(std::size_t(res.irradiance_r) * std::size_t(res.irradiance_mu_s) * 3u);
    parallel_for(std::size_t(res.irradiance_r) * std::size_t(res.irradiance_mu_s), 1, [&](std::size_t b, std::size_t e) {
        for (std::size_t node = b; node < e; ++node) {
            const int i = int(node) / res.irradiance_mu_s, j = int(node) % res.irradiance_mu_s;
            const double h = double(hd.Rtop - hd.R0) * double(i) / double(res.irradiance_r - 1);
            const double mu_s = -1.0 + 2.0 * double(j) / double(res.irradiance_mu_s - 1);
            const glm::dvec3 sun(std::sqrt(std::max(0.0, 1.0 - mu_s * mu_s)), 0.0, mu_s);
            glm::dvec3 E(0.0);
            for (int a = 0; a < n; ++a) {
                const double th = (double(a) + 0.5) * dth;
                for (int c = 0; c < 2 * n; ++c) {
                    const double ph = (double(c) + 0.5) * dph;
                    const glm::dvec3 w(std::cos(ph) * std::sin(th), std::sin(ph) * std::sin(th), std::cos(th));
                    ObserverHD o;
                    o.r = float(double(hd.R0) + h);
                    o.h = float(h);
                    o.cv = float(w.z);
                    o.cvs = float(glm::dot(w, sun));
                    o.cs = float(mu_s);
                    E += glm::dvec3(sky_sum(hd, o, steps, spacing)) * (w.z * std::sin(th) * dth * dph);
                }
            }
            for (int k = 0; k < 3; ++k)
                out[node * 3 + std::size_t(k)] = float(E[k]);
            if (progress)
                progress->advance();
        }
    });
    return out;
}

} // namespace skybake::sky
