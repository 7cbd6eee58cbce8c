// The CUDA sky against the CPU path on the same inputs. Skips without a GPU.
// Metric: the largest relative difference of a sample's radiance, and for
// images Bruneton's GPU-vs-CPU criterion, PSNR >= 47 dB.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "skybake/core.h"
#include "skybake/error.h"
#include "skybake/sky.h"
#include "core/gpu_test.h"

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
    SKYBAKE_SKIP_WITHOUT_GPU();
    for (const char* preset : {"earth", "paper", "paper-dense"}) {
        SCOPED_TRACE(preset);
        const SkyModel model(atmosphere_preset(preset));
        const auto samples = draw_sky_samples(50000, 7);
        std::vector<glm::vec3> cpu(samples.size()), gpu(samples.size());
        evaluate_sky(model, samples, cpu, SkyMethod::Tables);
        evaluate_sky_cuda(model, samples, gpu);
        double worst = 0.0;
        for (std::size_t i = 0; i < samples.size(); ++i) {
            const double ref = std::max({double(cpu[i].x), double(cpu[i].y), double(cpu[i].z), 1e-7});
            for (int c = 0; c < 3; ++c)
                worst = std::max(worst, std::abs(double(gpu[i][c]) - double(cpu[i][c])) / ref);
        }
        EXPECT_LT(worst, 1e-4);
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
