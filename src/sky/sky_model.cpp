// Sky colour I(cos α0, cos β0, cos θ0, ρ0): Pietras & Rudnicki (seed 000)
// section II over the section I tables (sky_hd.h), or the exact reference
// (exact.cpp); batch evaluation over all cores.
#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>

#include "core/parallel.h"
#include "core/progress.h"
#include "skybake/error.h"
#include "sky/internal.h"
#include "sky/multiple_scattering_lut.h"
#include "sky/scattering_orders.h"
#include "sky/table_cache.h"

namespace skybake {

struct SkyModel::Impl {
    Atmosphere atmosphere;
    SkyModelOptions options;
    OpticalLengthTables tables;
    sky::AtmosphereHD hd;
    // Multiple scattering (empty for single scattering).
    std::vector<float> orders, psi, irradiance;
    double multiple_seconds = 0.0;
    bool multiple_cached = false;

    void build_multiple();
};

namespace {

void check_multiple_resolution(const MultipleScatteringResolution& m) {
    const auto in = [](int v, int lo, int hi) { return v >= lo && v <= hi; };
    if (!in(m.r, 2, 512) || !in(m.mu, 2, 1024) || !in(m.mu_s, 2, 512) || !in(m.nu, 2, 512))
        throw Error("the orders grid needs 2 to 512 nodes per axis (mu: 2 to 1024 per half)", "multiple");
    if (double(m.r) * 2.0 * m.mu * m.mu_s * m.nu > double(1 << 24))
        throw Error("the orders grid may have at most 16777216 nodes", "multiple");
    if (!in(m.sphere, 4, 256))
        throw Error("the sphere integrals need 4 to 256 polar samples", "multiple.sphere");
    if (!in(m.psi_r, 2, 4096) || !in(m.psi_mu_s, 2, 4096) || !in(m.irradiance_r, 2, 4096) ||
        !in(m.irradiance_mu_s, 2, 4096))
        throw Error("the psi and irradiance tables need 2 to 4096 nodes per axis", "multiple");
    if (!(m.mu_s_min > -1.0 && m.mu_s_min <= 0.0))
        throw Error("mu_s_min must be in (-1, 0]", "multiple.mu_s_min");
}

} // namespace

void SkyModel::Impl::build_multiple() {
    if (atmosphere.scattering != Scattering::Multiple)
        return;
    const auto start = std::chrono::steady_clock::now();
    const MultipleScatteringResolution& res = options.multiple;
    const bool orders_method = atmosphere.multiple_method == MultipleScatteringMethod::Orders;
    sky::MultipleHD& m = hd.ms;
    m.mu_s_min = float(res.mu_s_min);
    m.x_horizon = float(sky::grid4_mus_coordinate(atmosphere.planet_radius_km, atmosphere.top_radius_km, res.mu_s_min, 0.0));
    const auto point_at_main = [&](std::vector<float>& table) {
        if (orders_method) {
            orders = std::move(table);
            m.method = sky::kMultipleOrders;
            m.orders = orders.data();
            m.nr = res.r;
            m.nmu = res.mu;
            m.nmus = res.mu_s;
            m.nnu = res.nu;
        } else {
            psi = std::move(table);
            m.method = sky::kMultipleHillaire;
            m.psi = psi.data();
            m.psi_nr = res.psi_r;
            m.psi_nmus = res.psi_mu_s;
        }
    };
    const std::size_t main_floats = orders_method ? std::size_t(res.r) * 2u * std::size_t(res.mu) *
                                                        std::size_t(res.mu_s) * std::size_t(res.nu) * 3u
                                                  : std::size_t(res.psi_r) * std::size_t(res.psi_mu_s) * 3u;
    const std::size_t irradiance_floats = std::size_t(res.irradiance_r) * std::size_t(res.irradiance_mu_s) * 3u;

    const std::filesystem::path cache = sky_table_cache_dir();
    const std::string key = cache.empty() ? std::string() : sky::multiple_tables_key(atmosphere, options);
    sky::CachedTables cached;
    if (!cache.empty() && sky::load_cached_tables(cache, key, main_floats, irradiance_floats, cached)) {
        point_at_main(cached.main);
        irradiance = std::move(cached.irradiance);
        multiple_cached = true;
    } else {
        const std::uint64_t main_units =
            orders_method ? sky::ScatteringOrders::progress_units(res, atmosphere.scattering_orders)
                          : std::uint64_t(res.psi_r) * std::uint64_t(res.psi_mu_s);
        Progress progress("multiple scattering", main_units + std::uint64_t(res.irradiance_r) *
                                                                   std::uint64_t(res.irradiance_mu_s));
        std::vector<float> table =
            orders_method
                ? sky::ScatteringOrders::compute(atmosphere, res, atmosphere.scattering_orders, false, &progress)
                      .residual()
                : sky::hillaire_psi_table(atmosphere, res, &progress);
        point_at_main(table);
        irradiance = sky::sky_irradiance_table(hd, res, options.steps,
                                               options.uniform_steps ? sky::kStepsUniform : sky::kStepsGraded,
                                               &progress);
        progress.finish();
        if (!cache.empty())
            sky::store_cached_tables(cache, key, {orders_method ? orders : psi, irradiance});
    }
    m.irradiance = irradiance.data();
    m.irr_nr = res.irradiance_r;
    m.irr_nmus = res.irradiance_mu_s;
    multiple_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

SkyModel::SkyModel(Atmosphere atmosphere, const SkyModelOptions& options) : impl_(std::make_unique<Impl>()) {
    atmosphere.validate();
    if (options.steps < 1 || options.steps > 1 << 20)
        throw Error("the number of steps must be 1 to 1048576", "steps");
    if (options.tables.shells < 2 || options.tables.cosines < 2 || options.tables.shells > 1 << 14 ||
        options.tables.cosines > 1 << 14)
        throw Error("table resolution must be 2 to 16384 in each dimension", "tables");
    impl_->atmosphere = std::move(atmosphere);
    impl_->options = options;
    impl_->tables = OpticalLengthTables::build(impl_->atmosphere, options.tables);
    impl_->hd = sky::make_atmosphere_hd(impl_->atmosphere, impl_->tables);
    if (impl_->atmosphere.scattering == Scattering::Multiple)
        check_multiple_resolution(options.multiple);
    impl_->build_multiple();
}

SkyModel::~SkyModel() = default;
SkyModel::SkyModel(SkyModel&&) noexcept = default;
SkyModel& SkyModel::operator=(SkyModel&&) noexcept = default;

const Atmosphere& SkyModel::atmosphere() const { return impl_->atmosphere; }
const OpticalLengthTables& SkyModel::tables() const { return impl_->tables; }
const SkyModelOptions& SkyModel::options() const { return impl_->options; }
namespace sky {
const AtmosphereHD& atmosphere_hd(const SkyModel& model) { return model.impl_->hd; }
} // namespace sky

int SkyModel::spacing() const { return impl_->options.uniform_steps ? sky::kStepsUniform : sky::kStepsGraded; }

namespace {

// The three directions of a cosine triple in a frame with the observer's
// vertical along z and V in the x–z plane.
void directions_from_cosines(double cv, double cvs, double cs, glm::dvec3& V, glm::dvec3& L) {
    const double sv = std::sqrt(std::max(0.0, 1.0 - cv * cv));
    const double ss = std::sqrt(std::max(0.0, 1.0 - cs * cs));
    V = glm::dvec3(sv, 0.0, cv);
    double cphi = 1.0;
    if (sv * ss > 1e-12)
        cphi = std::clamp((cvs - cv * cs) / (sv * ss), -1.0, 1.0);
    const double sphi = std::sqrt(std::max(0.0, 1.0 - cphi * cphi));
    L = glm::dvec3(ss * cphi, ss * sphi, cs);
}

glm::dvec3 exact_radiance(const Atmosphere& atm, double r0, double cv, double cvs, double cs, double tol) {
    glm::dvec3 V, L;
    directions_from_cosines(cv, cvs, cs, V, L);
    const glm::dvec3 O(0.0, 0.0, r0);
    double enter, exit;
    bool ground;
    if (!sky::atmosphere_segment(atm, O, V, enter, exit, ground))
        return glm::dvec3(0.0);
    return sky::inscatter_exact(atm, O + enter * V, V, exit - enter, L, tol);
}

} // namespace

glm::dvec3 SkyModel::radiance(const SkySample& s, SkyMethod method) const {
    assert(is_valid_sky_sample(s, 1e-4));
    const sky::ObserverHD o = sky::make_observer(impl_->atmosphere, s);
    if (method == SkyMethod::Tables)
        return glm::dvec3(sky::sky_sum(impl_->hd, o, impl_->options.steps, spacing()));
    const double r0 = impl_->atmosphere.planet_radius_km + impl_->atmosphere.altitude_from_density(s.density);
    return exact_radiance(impl_->atmosphere, r0, s.cos_view_zenith, s.cos_view_sun, s.cos_sun_zenith,
                          impl_->options.exact_tolerance) +
           glm::dvec3(sky::multiple_residual(impl_->hd, o, impl_->options.steps, spacing()));
}

glm::dvec3 SkyModel::radiance_at_radius(double r0, double cv, double cvs, double cs, SkyMethod method) const {
    const sky::ObserverHD o = sky::make_observer(impl_->atmosphere, r0, cv, cvs, cs);
    if (method == SkyMethod::Tables)
        return glm::dvec3(sky::sky_sum(impl_->hd, o, impl_->options.steps, spacing()));
    return exact_radiance(impl_->atmosphere, r0, cv, cvs, cs, impl_->options.exact_tolerance) +
           glm::dvec3(sky::multiple_residual(impl_->hd, o, impl_->options.steps, spacing()));
}

glm::dvec3 SkyModel::multiple_radiance_at_radius(double r0, double cv, double cvs, double cs) const {
    return glm::dvec3(sky::multiple_residual(impl_->hd, sky::make_observer(impl_->atmosphere, r0, cv, cvs, cs),
                                             impl_->options.steps, spacing()));
}

glm::dvec3 SkyModel::sky_irradiance(double altitude_km, double cos_sun_zenith) const {
    const sky::AtmosphereHD& a = impl_->hd;
    return glm::dvec3(sky::sky_irradiance_lookup(a.ms, a.R0, a.Rtop, float(altitude_km), float(cos_sun_zenith)));
}

double SkyModel::multiple_precompute_seconds() const { return impl_->multiple_seconds; }
bool SkyModel::multiple_tables_from_cache() const { return impl_->multiple_cached; }

std::size_t SkyModel::multiple_table_bytes() const {
    return (impl_->orders.size() + impl_->psi.size() + impl_->irradiance.size()) * sizeof(float);
}

glm::dvec3 SkyModel::radiance_tables(const SkySample& s, int steps, bool uniform_steps) const {
    return glm::dvec3(sky::seed_sky_sum(impl_->hd, sky::make_observer(impl_->atmosphere, s), steps,
                                        uniform_steps ? sky::kStepsUniform : sky::kStepsGraded));
}

void evaluate_sky(const SkyModel& model, std::span<const SkySample> samples, std::span<glm::vec3> out,
                  SkyMethod method) {
    assert(samples.size() == out.size());
    if (method == SkyMethod::Tables) {
        const sky::AtmosphereHD& hd = sky::atmosphere_hd(model);
        const Atmosphere& atm = model.atmosphere();
        const int steps = model.options().steps;
        const int spacing = model.options().uniform_steps ? sky::kStepsUniform : sky::kStepsGraded;
        parallel_for(samples.size(), 1024, [&](std::size_t begin, std::size_t end) {
            for (std::size_t i = begin; i < end; ++i)
                out[i] = sky::sky_sum(hd, sky::make_observer(atm, samples[i]), steps, spacing);
        });
        return;
    }
    parallel_for(samples.size(), 1, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
            out[i] = glm::vec3(model.radiance(samples[i], SkyMethod::Exact));
    });
}

void sky::evaluate_sky_split(const SkyModel& model, std::span<const SkySample> samples, std::span<glm::vec3> out,
                             std::span<const float> scale, int component) {
    const sky::AtmosphereHD& hd0 = sky::atmosphere_hd(model);
    const Atmosphere& atm = model.atmosphere();
    const std::size_t n = atm.components.size();
    assert(out.size() == samples.size() * n);
    assert(scale.empty() || (scale.size() == samples.size() && component >= 0 && std::size_t(component) < n));
    const int steps = model.options().steps;
    const int spacing = model.options().uniform_steps ? sky::kStepsUniform : sky::kStepsGraded;
    parallel_for(samples.size(), 1024, [&](std::size_t begin, std::size_t end) {
        sky::AtmosphereHD hd = hd0;
        for (std::size_t i = begin; i < end; ++i) {
            if (!scale.empty()) {
                hd.comp[component].sca = hd0.comp[component].sca * scale[i];
                hd.comp[component].ext = hd0.comp[component].ext * scale[i];
            }
            glm::vec3 parts[sky::kMaxComponents];
            sky::seed_sky_sum_split(hd, sky::make_observer(atm, samples[i]), steps, spacing, parts);
            for (std::size_t k = 0; k < n; ++k)
                out[i * n + k] = parts[k];
        }
    });
}

void evaluate_sky(const Atmosphere& atmosphere, std::span<const SkySample> samples, std::span<glm::vec3> out,
                  SkyMethod method) {
    const SkyModel model(atmosphere);
    evaluate_sky(model, samples, out, method);
}

} // namespace skybake
