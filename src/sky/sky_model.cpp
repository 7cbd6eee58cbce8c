// Sky colour I(cos α0, cos β0, cos θ0, ρ0): Pietras & Rudnicki (seed 000)
// section II over the section I tables (sky_hd.h), or the exact reference
// (exact.cpp); batch evaluation over all cores.
#include <algorithm>
#include <cassert>
#include <cmath>

#include "core/parallel.h"
#include "skybake/error.h"
#include "sky/internal.h"

namespace skybake {

struct SkyModel::Impl {
    Atmosphere atmosphere;
    SkyModelOptions options;
    OpticalLengthTables tables;
    sky::AtmosphereHD hd;
};

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
    if (method == SkyMethod::Tables)
        return glm::dvec3(sky::seed_sky_sum(impl_->hd, sky::make_observer(impl_->atmosphere, s), impl_->options.steps, spacing()));
    const double r0 = impl_->atmosphere.planet_radius_km + impl_->atmosphere.altitude_from_density(s.density);
    return exact_radiance(impl_->atmosphere, r0, s.cos_view_zenith, s.cos_view_sun, s.cos_sun_zenith,
                          impl_->options.exact_tolerance);
}

glm::dvec3 SkyModel::radiance_at_radius(double r0, double cv, double cvs, double cs, SkyMethod method) const {
    if (method == SkyMethod::Tables)
        return glm::dvec3(
            sky::seed_sky_sum(impl_->hd, sky::make_observer(impl_->atmosphere, r0, cv, cvs, cs), impl_->options.steps, spacing()));
    return exact_radiance(impl_->atmosphere, r0, cv, cvs, cs, impl_->options.exact_tolerance);
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
                out[i] = sky::seed_sky_sum(hd, sky::make_observer(atm, samples[i]), steps, spacing);
        });
        return;
    }
    parallel_for(samples.size(), 1, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
            out[i] = glm::vec3(model.radiance(samples[i], SkyMethod::Exact));
    });
}

void evaluate_sky(const Atmosphere& atmosphere, std::span<const SkySample> samples, std::span<glm::vec3> out,
                  SkyMethod method) {
    const SkyModel model(atmosphere);
    evaluate_sky(model, samples, out, method);
}

} // namespace skybake
