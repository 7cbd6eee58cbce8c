// The CUDA sky against the CPU path on the same inputs. Skips without a GPU.
// Metric: per-sample differences against a rounding model measured on the
// CPU (see SamplesMatchTheCpu), and for images Bruneton's GPU-vs-CPU
// criterion, PSNR >= 47 dB.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "skybake/core.h"
#include "skybake/error.h"
#include "skybake/sky.h"
#include "core/gpu_test.h"
#include "sky/rounding_model_test_util.h"

using namespace skybake;

namespace {
double psnr_db(const Image& a, const Image& b) {
    double peak = 0.0, se = 0.0;
    for (std::size_t i = 0; i < a.rgb.size(); ++i) {
        peak = std::max(peak, double(a.rgb[i]));
        const double d = double(a.rgb[i]) - double(b.rgb[i]);
        se += d * d;
    }
    const double mse = se / double(a.rgb.size());
    return mse > 0.0 ? 10.0 * std::log10(peak * peak / mse) : 1e9;
}
} // namespace

TEST(SkyCuda, WithoutADeviceTheErrorIsClear) {
    if (cuda_device_count() > 0)
        GTEST_SKIP() << "a CUDA device is present";
    const SkyModel model(atmosphere_preset("earth"));
    std::vector<SkySample> s(4);
    std::vector<glm::vec3> out(4);
    EXPECT_THROW(evaluate_sky_cuda(model, s, out), Error);
    EXPECT_THROW(render_sky_cuda(model, SkyRenderSettings{}), Error);
}

TEST(SkyCuda, SamplesMatchTheCpu) {
    // Metric (rounding_model_test_util.h): per sample, the largest channel
    // difference over the sample's largest channel, floored at 1e-3 of the
    // brightest. The bulk moves by rounding only: p50 ≤ 1e-5, p90 ≤ 1e-4.
    // Beyond that a sample may differ by as much as the CPU's own sensitivity
    // to its inputs (twice it, or 1e-4), since near the step split or a shadow
    // boundary other rounding flips a discrete choice; at most 1e-4 of the
    // samples may fall outside that model.
    SKYBAKE_SKIP_WITHOUT_GPU();
    for (const char* preset : {"earth", "paper", "paper-dense"}) {
        SCOPED_TRACE(preset);
        const SkyModel model(atmosphere_preset(preset));
        const auto samples = draw_sky_samples(50000, 7);
        std::vector<glm::vec3> cpu(samples.size()), gpu(samples.size());
        evaluate_sky(model, samples, cpu, SkyMethod::Tables);
        evaluate_sky_cuda(model, samples, gpu);
        const double floor = sky_test::difference_floor(cpu);
        const std::vector<double> sensitivity = sky_test::rounding_sensitivity(model, samples, cpu, floor);
        std::vector<double> diff(samples.size());
        std::size_t lit = 0, unexplained = 0;
        for (std::size_t i = 0; i < samples.size(); ++i) {
            diff[i] = sky_test::sample_difference(gpu[i], cpu[i], floor);
            lit += std::max({cpu[i].x, cpu[i].y, cpu[i].z}) > 0.0f;
            unexplained += diff[i] > std::max(1e-4, 2.0 * sensitivity[i]);
        }
        const double p50 = sky_test::quantile(diff, 0.5), p90 = sky_test::quantile(diff, 0.9);
        std::printf("%s: %zu lit of %zu; GPU - CPU p50 %.1e, p90 %.1e, max %.1e; %zu outside the rounding model\n",
                    preset, lit, samples.size(), p50, p90, *std::max_element(diff.begin(), diff.end()), unexplained);
        EXPECT_GE(lit, samples.size() / 4);
        EXPECT_LE(p50, 1e-5);
        EXPECT_LE(p90, 1e-4);
        EXPECT_LE(double(unexplained), 1e-4 * double(samples.size()));
    }
}

TEST(SkyCuda, RenderMatchesTheCpu) {
    SKYBAKE_SKIP_WITHOUT_GPU();
    const SkyModel model(atmosphere_preset("earth"));
    for (SkyView view : {SkyView::Fisheye, SkyView::Panorama, SkyView::Camera}) {
        SkyRenderSettings s;
        s.view = view;
        s.width = 160;
        s.height = 96;
        s.sun_elevation_deg = 12.0;
        s.pitch_deg = 10.0;
        EXPECT_GE(psnr_db(render_sky(model, s), render_sky_cuda(model, s)), 47.0) << int(view);
    }
    SkyRenderSettings space;
    space.view = SkyView::Camera;
    space.altitude_km = 20000.0;
    space.pitch_deg = -90.0;
    space.fov_deg = 60.0;
    space.width = 128;
    space.height = 96;
    EXPECT_GE(psnr_db(render_sky(model, space), render_sky_cuda(model, space)), 47.0);
}

// Multiple scattering on the GPU: the orders grid and Hillaire's march are the
// same SKYBAKE_HD code as the CPU's, uploaded with the model's tables.
TEST(SkyCuda, MultipleScatteringMatchesTheCpu) {
    SKYBAKE_SKIP_WITHOUT_GPU();
    for (MultipleScatteringMethod method : {MultipleScatteringMethod::Orders, MultipleScatteringMethod::Hillaire}) {
        SCOPED_TRACE(multiple_scattering_method_name(method));
        Atmosphere atm = atmosphere_preset("earth");
        atm.scattering = Scattering::Multiple;
        atm.multiple_method = method;
        const SkyModel model(atm);
        const auto samples = draw_sky_samples(20000, 11);
        std::vector<glm::vec3> cpu(samples.size()), gpu(samples.size());
        evaluate_sky(model, samples, cpu, SkyMethod::Tables);
        evaluate_sky_cuda(model, samples, gpu);
        const double floor = sky_test::difference_floor(cpu);
        std::vector<double> diff(samples.size());
        for (std::size_t i = 0; i < samples.size(); ++i)
            diff[i] = sky_test::sample_difference(gpu[i], cpu[i], floor);
        const double p50 = sky_test::quantile(diff, 0.5), p99 = sky_test::quantile(diff, 0.99);
        std::printf("%s: GPU - CPU p50 %.1e, p99 %.1e\n", multiple_scattering_method_name(method), p50, p99);
        EXPECT_LE(p50, 1e-5);
        EXPECT_LE(p99, 1e-3);
        SkyRenderSettings s;
        s.view = SkyView::Fisheye;
        s.width = 128;
        s.height = 128;
        s.sun_elevation_deg = -4.0; // twilight: the multiple part dominates
        EXPECT_GE(psnr_db(render_sky(model, s), render_sky_cuda(model, s)), 47.0);
    }
}
