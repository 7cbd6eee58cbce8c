// For tests: how far the table path's radiance may legitimately move when the
// same sample is evaluated with other rounding (the CUDA kernels: another
// sqrtf, logf and expf, and contracted multiply-adds).
//
// Most samples move by float rounding alone (~1e-6). A few sit on a boundary
// of the sum's discrete choices, the split of the steps around the ray's
// lowest point (seed_sky_sum, sky_hd.h) or a planet-shadow test
// (in_planet_shadow), and flip: one step more on one side, one shadowed point
// less. The model measures those flips on the CPU by evaluating every sample
// again with each input moved by a few ulps: the distribution of the changes
// is the one other rounding produces.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "skybake/sky.h"

namespace skybake::sky_test {

// The metric of a sample's difference: the largest channel difference over
// the sample's largest channel, or over `floor` where that is dimmer (dim
// samples, such as a short ray into the ground from a metre up, are
// ill-conditioned in float and would otherwise dominate).
inline double sample_difference(const glm::vec3& a, const glm::vec3& b, double floor) {
    const double ref = std::max({double(b.x), double(b.y), double(b.z), floor});
    double d = 0.0;
    for (int c = 0; c < 3; ++c)
        d = std::max(d, std::abs(double(a[c]) - double(b[c])) / ref);
    return d;
}

// 1e-3 of the brightest sample's largest channel.
inline double difference_floor(const std::vector<glm::vec3>& base) {
    double m = 0.0;
    for (const glm::vec3& b : base)
        m = std::max({m, double(b.x), double(b.y), double(b.z)});
    return 1e-3 * m;
}

// Per sample, the largest sample_difference seen when any one input moves by
// 1, 4 or 16 ulps either way.
inline std::vector<double> rounding_sensitivity(const SkyModel& model, const std::vector<SkySample>& samples,
                                                const std::vector<glm::vec3>& base, double floor) {
    std::vector<SkySample> moved;
    std::vector<std::size_t> owner;
    for (std::size_t i = 0; i < samples.size(); ++i)
        for (int field = 0; field < 4; ++field)
            for (int step : {-16, -4, -1, 1, 4, 16}) {
                SkySample s = samples[i];
                float* f = field == 0   ? &s.cos_view_zenith
                           : field == 1 ? &s.cos_view_sun
                           : field == 2 ? &s.cos_sun_zenith
                                        : &s.density;
                for (int k = 0; k < std::abs(step); ++k)
                    *f = std::nextafter(*f, step > 0 ? 2.0f : -2.0f);
                if (!is_valid_sky_sample(s, 0.0))
                    continue;
                moved.push_back(s);
                owner.push_back(i);
            }
    std::vector<glm::vec3> out(moved.size());
    evaluate_sky(model, moved, out, SkyMethod::Tables);
    std::vector<double> change(samples.size(), 0.0);
    for (std::size_t j = 0; j < moved.size(); ++j)
        change[owner[j]] = std::max(change[owner[j]], sample_difference(out[j], base[owner[j]], floor));
    return change;
}

// The q-quantile of a list (copied).
inline double quantile(std::vector<double> v, double q) {
    if (v.empty())
        return 0.0;
    const auto k = std::size_t(q * double(v.size() - 1));
    std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(k), v.end());
    return v[k];
}

} // namespace skybake::sky_test
