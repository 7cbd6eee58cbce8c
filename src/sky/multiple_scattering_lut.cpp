// Hillaire S. A Scalable and Production Ready Sky and Atmosphere Rendering
// Technique. EGSR 2020, section 5.5: the multiple-scattering table.
//
// At a point x with the sun at μs, in a medium assumed isotropic (p_u = 1/4π):
//   L2   = ∫_4π p_u [∫_0^d σs(y) T(x, y) T_sun(y) p_u dt + T(x, g) (albedo/π) μs,g T_sun(g)] dω
//   f_ms = ∫_4π p_u ∫_0^d σs(y) T(x, y) dt dω
//   ψms  = L2 / (1 − f_ms)            (the orders 2, 3, … as a geometric series)
// and along a view ray the multiple scattering is ∫ σs(y) ψms(y) T dt (sky_hd.h).
#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "core/parallel.h"
#include "core/progress.h"
#include "sky/multiple_scattering_lut.h"
#include "sky/transmittance_table.h"

namespace skybake::sky {

namespace {
constexpr double kPiD = 3.14159265358979323846;
constexpr int kRayPoints = 40;
} // namespace

std::vector<float> hillaire_psi_table(const Atmosphere& atm, const MultipleScatteringResolution& res,
                                      Progress* progress) {
    const TransmittanceTable T(atm);
    const double R0 = atm.planet_radius_km, Rt = atm.top_radius_km, scale = sharpest_scale_height(atm);
    const double pu = 0.25 / kPiD;
    const int n = res.sphere;
    const double dang = kPiD / double(n);
    std::vector<float> out(std::size_t(res.psi_r) * std::size_t(res.psi_mu_s) * 3u);
    parallel_for(std::size_t(res.psi_r) * std::size_t(res.psi_mu_s), 1, [&](std::size_t b, std::size_t e) {
        for (std::size_t node = b; node < e; ++node) {
            const int i = int(node) / res.psi_mu_s, j = int(node) % res.psi_mu_s;
            const double r = R0 + (Rt - R0) * double(i) / double(res.psi_r - 1);
            const double mu_s = -1.0 + 2.0 * double(j) / double(res.psi_mu_s - 1);
            const glm::dvec3 sun(std::sqrt(std::max(0.0, 1.0 - mu_s * mu_s)), 0.0, mu_s);
            glm::dvec3 L2(0.0), fms(0.0);
            for (int a = 0; a < n; ++a) {
                const double th = (double(a) + 0.5) * dang;
                for (int c = 0; c < 2 * n; ++c) {
                    const double ph = (double(c) + 0.5) * dang;
                    const glm::dvec3 w(std::cos(ph) * std::sin(th), std::sin(ph) * std::sin(th), std::cos(th));
                    const double domega = std::sin(th) * dang * dang;
                    const double nu = glm::dot(w, sun);
                    const double dg = ray_ground_distance(R0, r, w.z);
                    const bool ground = dg >= 0.0;
                    const double d = ground ? dg : ray_top_distance(Rt, r, w.z);
                    glm::dvec3 lf(0.0), f(0.0);
                    for_each_ray_midpoint(R0, scale, r, w.z, d, kRayPoints, [&](double t, double dt) {
                        const double rt = std::max(R0, ray_radius(r, w.z, t));
                        const glm::dvec3 s = scattering_at_altitude(atm, rt - R0) * T.between(r, w.z, t, ground) * dt;
                        f += s;
                        lf += s * T.sun(rt, std::clamp((r * mu_s + t * nu) / rt, -1.0, 1.0)) * pu;
                    });
                    if (ground) {
                        const double mu_g = glm::dot((glm::dvec3(0.0, 0.0, r) + dg * w) / R0, sun);
                        if (mu_g > 0.0)
                            lf += T.between(r, w.z, dg, true) * atm.ground_albedo / kPiD * mu_g * T.sun(R0, mu_g);
                    }
                    L2 += lf * pu * domega;
                    fms += f * pu * domega;
                }
            }
            const glm::dvec3 psi = L2 / (glm::dvec3(1.0) - fms);
            for (int k = 0; k < 3; ++k)
                out[node * 3 + std::size_t(k)] = float(psi[k]);
            if (progress)
                progress->advance();
        }
    });
    return out;
}

} // namespace skybake::sky
