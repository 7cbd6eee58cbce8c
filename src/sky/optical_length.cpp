// Optical-length tables: Pietras & Rudnicki (seed 000), section I.
//
// Shells are uniform in the table coordinate u (relative density ρ_i = i/n for
// exponential components, as in the seed). One shell between an inner radius b
// and an outer radius a adds, for a ray leaving radius b with cosine c,
//     s = sqrt(a² − b²(1 − c²)) − b c     (the seed's sqrt(a² − b² sin²α) − b cos α)
// weighted by a density (the seed: ρ_i, the outer boundary's), and the cosine
// is carried to the next shell by
//     c' = sqrt(a² − b²(1 − c²)) / a.
// L[u, c] sums the shells from the row's radius up to the top. The seed's S
// table is kept (S[row, c] is the shell just outside the row). When summing L,
// s is evaluated at the carried cosine itself rather than read back from the
// S grid, which would add interpolation error where S is steep (c → 0).
//
// The seed lets ρ_0 = 0 reach infinity; here every radius is clamped to the
// top of the atmosphere, so shells above the top have zero length.
#include <algorithm>
#include <cassert>
#include <cmath>

#include "core/parallel.h"
#include "sky/internal.h"

namespace skybake {

namespace {

struct ShellGeometry {
    std::vector<double> radius; // per row, km (clamped to the top)
    std::vector<double> height; // per row, km above the ground
    int outward = -1;           // row step towards the top: −1 (density axis) or +1 (altitude axis)
};

ShellGeometry shell_geometry(const Atmosphere& atm, const AtmosphereComponent& comp, int n) {
    ShellGeometry g;
    g.radius.resize(std::size_t(n) + 1);
    g.height.resize(std::size_t(n) + 1);
    const double top_h = atm.top_radius_km - atm.planet_radius_km;
    const bool density_axis = comp.profile == DensityProfile::Exponential;
    g.outward = density_axis ? -1 : +1;
    for (int i = 0; i <= n; ++i) {
        const double u = double(i) / double(n);
        double h = density_axis ? (i == 0 ? top_h : -comp.scale_height_km * std::log(u)) : u * top_h;
        h = std::min(h, top_h);
        g.height[std::size_t(i)] = h;
        g.radius[std::size_t(i)] = atm.planet_radius_km + h;
    }
    return g;
}

// Mean density over the heights [h_in, h_out].
double mean_density(const AtmosphereComponent& comp, double h_in, double h_out) {
    if (comp.profile == DensityProfile::Exponential) {
        const double H = comp.scale_height_km;
        return H * (std::exp(-h_in / H) - std::exp(-h_out / H)) / (h_out - h_in);
    }
    if (comp.profile == DensityProfile::Constant)
        return 1.0;
    // Tent: piecewise linear; the midpoint rule on 64 sub-intervals is exact
    // except on the sub-interval holding a kink.
    double sum = 0.0;
    for (int k = 0; k < 64; ++k)
        sum += relative_density(comp, h_in + (h_out - h_in) * (k + 0.5) / 64.0);
    return sum / 64.0;
}

// Sub-shells per shell: one for the seed's rule; for the refined rule enough
// that none is thicker than a sixteenth of the profile's length scale.
int sub_shells(const AtmosphereComponent& comp, TableRule rule, double h_in, double h_out) {
    if (rule == TableRule::AsPublished || h_out <= h_in)
        return 1;
    double scale = comp.profile == DensityProfile::Exponential ? comp.scale_height_km
                   : comp.profile == DensityProfile::Tent      ? comp.tent_half_width_km
                                                               : 1e9;
    return int(std::min(4096.0, std::ceil((h_out - h_in) / (scale / 16.0))));
}

// Length of the path from radius b (cosine c, c ≥ 0) to radius a > b, and the
// cosine there. Written as (a² − b²)/(sqrt(·) + b c) to avoid cancellation.
inline double shell_step(double a, double b, double c, double& c_out) {
    const double q = std::sqrt(std::max(0.0, a * a - b * b * (1.0 - c * c)));
    c_out = std::min(1.0, q / a);
    const double denom = q + b * c;
    return denom > 0.0 ? (a - b) * (a + b) / denom : 0.0;
}

struct SubShell {
    double r_in, r_out, weight; // radii in km, density weight
};

// The sub-shells of the shell between heights h_in < h_out. The seed's rule:
// one, weighted by ρ_i, the density at the outer boundary. The refined rule:
// sub-shells at most a sixteenth of the profile's length scale thick, each
// weighted by its mean density; for exponential profiles one sub-shell covers
// everything above 18 scale heights (density < 2e-8).
std::vector<SubShell> sub_shells_of(const AtmosphereComponent& comp, TableRule rule, double R0, double h_in,
                                    double h_out) {
    std::vector<SubShell> out;
    if (!(h_out > h_in))
        return out;
    if (rule == TableRule::AsPublished) {
        out.push_back({R0 + h_in, R0 + h_out, relative_density(comp, h_out)});
        return out;
    }
    double h_fine = h_out;
    if (comp.profile == DensityProfile::Exponential)
        h_fine = std::clamp(18.0 * comp.scale_height_km, h_in, h_out);
    const int k = sub_shells(comp, rule, h_in, h_fine);
    for (int i = 0; i <= k; ++i) {
        const double lo = i < k ? h_in + (h_fine - h_in) * i / k : h_fine;
        const double hi = i < k ? h_in + (h_fine - h_in) * (i + 1) / k : h_out;
        if (hi > lo)
            out.push_back({R0 + lo, R0 + hi, mean_density(comp, lo, hi)});
    }
    return out;
}

} // namespace

OpticalLengthTables OpticalLengthTables::build(const Atmosphere& atm, const TableResolution& res) {
    atm.validate();
    assert(res.shells >= 2 && res.cosines >= 2);
    OpticalLengthTables t;
    t.atmosphere_ = atm;
    t.resolution_ = res;
    const int n = res.shells, m = res.cosines;
    const std::size_t rows = std::size_t(n) + 1, cols = std::size_t(m) + 1;
    for (const AtmosphereComponent& comp : atm.components) {
        const ShellGeometry g = shell_geometry(atm, comp, n);
        // Sub-shells of the shell just outside each row.
        const double R0 = atm.planet_radius_km;
        std::vector<std::vector<SubShell>> shells(rows);
        for (std::size_t i = 0; i < rows; ++i) {
            const long o = long(i) + g.outward;
            if (o >= 0 && o < long(rows))
                shells[i] = sub_shells_of(comp, atm.table_rule, R0, g.height[i], g.height[std::size_t(o)]);
        }
        std::vector<float> S(rows * cols, 0.0f), L(rows * cols, 0.0f);
        parallel_for(rows, 1, [&](std::size_t begin, std::size_t end) {
            for (std::size_t i = begin; i < end; ++i) {
                for (std::size_t j = 0; j < cols; ++j) {
                    // L: all shells up to the top, carrying the cosine; S: the first one.
                    double c = double(j) / double(m), sum = 0.0;
                    for (long row = long(i); row >= 0 && row < long(rows); row += g.outward) {
                        const auto& list = shells[std::size_t(row)];
                        if (list.empty())
                            break; // at the top
                        double part = 0.0;
                        for (const SubShell& sub : list) {
                            double c_next;
                            part += sub.weight * shell_step(sub.r_out, sub.r_in, c, c_next);
                            c = c_next;
                        }
                        if (row == long(i))
                            S[i * cols + j] = float(part);
                        sum += part;
                    }
                    L[i * cols + j] = float(sum);
                }
            }
        });
        t.shell_.push_back(std::move(S));
        t.length_.push_back(std::move(L));
    }
    return t;
}

double OpticalLengthTables::optical_length(int component, double altitude_km, double cos_zenith) const {
    assert(component >= 0 && component < components());
    const sky::AtmosphereHD a = sky::make_atmosphere_hd(atmosphere_, *this);
    const sky::ComponentHD& c = a.comp[component];
    const float h = float(altitude_km);
    const float r = float(atmosphere_.planet_radius_km + altitude_km);
    const float u = sky::table_coordinate(a, c, h, sky::component_density(c, h));
    return sky::optical_length_lookup(a, c, r, u, float(std::clamp(cos_zenith, -1.0, 1.0)));
}

namespace sky {

AtmosphereHD make_atmosphere_hd(const Atmosphere& atm, const OpticalLengthTables& tables) {
    AtmosphereHD a;
    a.R0 = float(atm.planet_radius_km);
    a.Rtop = float(atm.top_radius_km);
    a.count = int(atm.components.size());
    assert(a.count <= kMaxComponents && tables.components() == a.count);
    for (int k = 0; k < a.count; ++k) {
        const AtmosphereComponent& src = atm.components[std::size_t(k)];
        ComponentHD& c = a.comp[k];
        c.profile = int(src.profile);
        c.inv_scale_height = float(1.0 / src.scale_height_km);
        c.tent_center = float(src.tent_center_km);
        c.inv_tent_half_width = float(1.0 / src.tent_half_width_km);
        c.sca = glm::vec3(src.scattering_per_km);
        c.ext = glm::vec3(src.extinction_per_km);
        c.phase = int(src.phase);
        c.g = float(src.phase_g);
        c.axis = src.profile == DensityProfile::Exponential ? kAxisDensity : kAxisAltitude;
        c.table.L = tables.length_table(k).data();
        c.table.rows = tables.rows();
        c.table.cols = tables.columns();
    }
    return a;
}

ObserverHD make_observer(const Atmosphere& atm, double radius_km, double cv, double cvs, double cs) {
    ObserverHD o;
    o.r = float(radius_km);
    o.h = float(radius_km - atm.planet_radius_km);
    o.cv = float(cv);
    o.cvs = float(cvs);
    o.cs = float(cs);
    return o;
}

ObserverHD make_observer(const Atmosphere& atm, const SkySample& s) {
    const double h = atm.altitude_from_density(double(s.density));
    ObserverHD o;
    o.r = float(atm.planet_radius_km + h);
    o.h = float(h);
    o.cv = s.cos_view_zenith;
    o.cvs = s.cos_view_sun;
    o.cs = s.cos_sun_zenith;
    return o;
}

} // namespace sky

} // namespace skybake
