// Slow tests of the neural sky: training at a useful scale on the `earth`
// preset (200,000 samples): the seed's topology learns the sky to the accuracy
// documented in docs/neural.md, a larger topology does better on the same
// data, the error report agrees with an independent recomputation, and the
// default network of `sky train` (one full run) meets its documented accuracy.
#include <cmath>
#include <cstdio>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "skybake/neural.h"

using namespace skybake;

namespace {

const SkyModel& earth() {
    static const SkyModel m(atmosphere_preset("earth"));
    return m;
}

NeuralSky train(const char* topology, int epochs, int lm) {
    NeuralTrainOptions o;
    o.topology = parse_topology(topology);
    o.samples = 200000;
    o.adam_epochs = epochs;
    o.lm_iterations = lm;
    o.progress = false;
    return train_neural_sky(earth(), o);
}

} // namespace

TEST(NeuralSlow, SeedTopologyLearnsAndLargerIsBetter) {
    const NeuralSky paper = train("paper", 30, 15);
    const NeuralSky wide = train("independent:16x16", 80, 5);
    // docs/neural.md: the seed's topology reaches a held-out RMS of about
    // 0.027 on 800,000 samples; a constant predictor has about 0.25. On these
    // 200,000 samples, measured: 0.0347 (paper) and 0.0237 (16x16); day
    // medians 0.286 and 0.079. Each bound is about 1.3× its figure.
    EXPECT_LT(paper.training.heldout_rms, 0.045);
    EXPECT_LT(wide.training.heldout_rms, 0.031);
    EXPECT_LT(wide.training.heldout_rms, 0.8 * paper.training.heldout_rms);

    NeuralErrorOptions eo;
    eo.samples = 20000;
    eo.views = false;
    const NeuralErrorReport a = measure_neural_sky_error(paper, eo);
    const NeuralErrorReport b = measure_neural_sky_error(wide, eo);
    std::printf("paper: held-out RMS %.4f, day p50 %.4f; independent:16x16: held-out RMS %.4f, day p50 %.4f\n",
                paper.training.heldout_rms, a.day.p50, wide.training.heldout_rms, b.day.p50);
    EXPECT_LT(a.day.p50, 0.37);
    EXPECT_LT(b.day.p50, 0.10);
    EXPECT_EQ(a.all.count, a.day.count + a.twilight.count);
    EXPECT_EQ(a.all.count + a.night.count, 20000u);

    // Independent recomputation of the day median from the public API.
    const std::vector<SkySample> s = draw_sky_samples(eo.samples, eo.seed);
    std::vector<glm::vec3> ref(s.size()), got(s.size());
    evaluate_sky(earth(), s, ref, SkyMethod::Tables);
    evaluate_neural_sky(paper, s, got);
    std::vector<double> day;
    for (std::size_t i = 0; i < s.size(); ++i)
        if (s[i].cos_sun_zenith > 0.0f && std::max({ref[i].x, ref[i].y, ref[i].z}) > 0.0f)
            day.push_back(double(glm::length(got[i] - ref[i]) / glm::length(ref[i])));
    std::nth_element(day.begin(), day.begin() + std::ptrdiff_t((day.size() - 1) / 2), day.end());
    EXPECT_NEAR(day[(day.size() - 1) / 2], a.day.p50, 1e-3 * a.day.p50);
}

TEST(NeuralSlow, ViewsOfATrainedNetworkResembleTheReference) {
    const NeuralSky net = train("independent:16x16", 30, 0);
    NeuralErrorOptions eo;
    eo.samples = 1000;
    eo.view_width = 120;
    eo.view_height = 80;
    const NeuralErrorReport r = measure_neural_sky_error(net, eo);
    ASSERT_EQ(r.views.size(), 6u);
    std::printf("independent:16x16, 30 epochs: mean view PSNR %.2f dB, worst %.2f dB\n", r.mean_view_psnr_db,
                r.min_view_psnr_db);
    // docs/neural.md: about 26 dB for this topology trained on 800,000 samples;
    // measured here (200,000 samples, 30 epochs) 22.8 dB mean, 19.6 dB worst.
    // 1.3× the mean squared error is 1.14 dB less.
    EXPECT_GT(r.mean_view_psnr_db, 21.6);
    EXPECT_GT(r.min_view_psnr_db, 18.4);
}

namespace {

// `skybake sky train --preset earth [--scattering multiple]` exactly:
// 800,000 samples of the refined 512 x 256 tables with 64 steps,
// shared:16x12, horizon inputs, the default (residual) outputs, 60 Adam
// epochs, 20 LM iterations.
NeuralSky train_the_default(Scattering scattering, double aerosol_max = 1.0) {
    Atmosphere atm = atmosphere_preset("earth");
    atm.table_rule = TableRule::Refined;
    atm.scattering = scattering;
    SkyModelOptions so;
    so.tables = kTrainingTargetTables;
    so.steps = kTrainingTargetSteps;
    NeuralTrainOptions o;
    o.topology = parse_topology(kDefaultTopology);
    o.inputs = InputEncoding::Horizon;
    o.outputs = default_output_encoding(atm);
    EXPECT_EQ(o.outputs, OutputEncoding::Residual);
    o.progress = false;
    if (aerosol_max > 1.0) { // `--aerosol-range 1:MAX`
        o.family_component = "mie";
        o.aerosol_max = aerosol_max;
    }
    return train_neural_sky(SkyModel(atm, so), o);
}

// The targets of a network of at most 400 weights on a flight's samples (5%
// over the lit ones, 15% at twilight) and in the views (35 dB mean, 30 dB at
// worst).
void expect_small_network_flight_targets(const NeuralErrorReport& r) {
    EXPECT_LT(r.flight_all.mean, 0.05);
    EXPECT_LT(r.flight_twilight.mean, 0.15);
    EXPECT_GT(r.mean_view_psnr_db, 35.0);
    EXPECT_GT(r.min_view_psnr_db, 30.0);
}

// And the same on the held-out samples.
void expect_small_network_targets(const NeuralErrorReport& r) {
    EXPECT_LT(r.all.mean, 0.05);
    EXPECT_LT(r.twilight.mean, 0.15);
    expect_small_network_flight_targets(r);
}

} // namespace

TEST(NeuralSlow, TheDefaultSmallNetworkMeetsItsDocumentedAccuracy) {
    const NeuralSky net = train_the_default(Scattering::Single);
    ASSERT_LE(net.topology.weight_count(), 400);
    const NeuralErrorReport r = measure_neural_sky_error(net);
    std::printf("%s (%d weights): mean %.2f%% (day %.2f%%, twilight %.2f%%), flight %.2f%% (twilight %.2f%%), "
                "views %.2f / %.2f dB\n",
                net.topology.name().c_str(), net.topology.weight_count(), 100 * r.all.mean, 100 * r.day.mean,
                100 * r.twilight.mean, 100 * r.flight_all.mean, 100 * r.flight_twilight.mean, r.mean_view_psnr_db,
                r.min_view_psnr_db);
    // docs/neural.md, "Accuracy": measured 1.50% (day 1.14%, twilight
    // 4.58%), flight 2.46% (twilight 10.2%), views 44.10 / 37.63 dB.
    expect_small_network_targets(r);
}

TEST(NeuralSlow, TheDefaultSmallNetworkOfTheWholeSkysLight) {
    // The same network and training on the total radiance (4 orders,
    // Bruneton's method): residual outputs with the multiply scattered
    // light's term, a correction of the isotropic march, and 40% of the
    // training samples a flight's.
    const NeuralSky net = train_the_default(Scattering::Multiple);
    ASSERT_TRUE(net.encoding.multiple);
    ASSERT_TRUE(net.encoding.multiple_marched());
    const NeuralErrorReport r = measure_neural_sky_error(net);
    std::printf("%s (%d weights), total radiance: day %.2f%%, twilight %.2f%%, flight %.2f%% (day %.2f%%, twilight "
                "%.2f%%), views %.2f / %.2f dB\n",
                net.topology.name().c_str(), net.topology.weight_count(), 100 * r.day.mean, 100 * r.twilight.mean,
                100 * r.flight_all.mean, 100 * r.flight_day.mean, 100 * r.flight_twilight.mean, r.mean_view_psnr_db,
                r.min_view_psnr_db);
    // docs/neural.md, "The whole sky's light": measured (800,000 samples)
    // day 2.99%, twilight 13.3%, flight 4.38% (day 2.63%, twilight 12.3%),
    // views 41.66 / 32.18 dB; with 30% a flight's, flight 5.03%. Before the
    // orders grid's radius fix, the log-encoded term had flight 20.7% (twilight 53.2%), 39.0 /
    // 31.0 dB. Bounds: the targets of at most 400 weights on the flight and
    // the views, the twilight's on the held-out samples (whose mean over
    // every lit sample, down to midnight's sky, is not met: 7.4%), and 1.3x
    // the day.
    EXPECT_LT(r.day.mean, 0.036);
    EXPECT_LT(r.twilight.mean, 0.15);
    expect_small_network_flight_targets(r);
}

TEST(NeuralSlow, TheDefaultSmallNetworkOfAnAerosolFamily) {
    // `skybake sky train --preset earth --aerosol-range 1:8`: one network for
    // 1 to 8 times the aerosol, the amount a fifth input.
    const NeuralSky net = train_the_default(Scattering::Single, 8.0);
    ASSERT_EQ(net.topology.inputs, 5);
    ASSERT_LE(net.topology.weight_count(), 400);
    const NeuralErrorReport r = measure_neural_sky_error(net);
    std::printf("%s family (%d weights), aerosol 1 to 8: mean %.2f%% (twilight %.2f%%), flight %.2f%% (twilight "
                "%.2f%%), %zu views %.2f / %.2f dB\n",
                net.topology.name().c_str(), net.topology.weight_count(), 100 * r.all.mean, 100 * r.twilight.mean,
                100 * r.flight_all.mean, 100 * r.flight_twilight.mean, r.views.size(), r.mean_view_psnr_db,
                r.min_view_psnr_db);
    // docs/neural.md, "A family of atmospheres": measured 1.47% (twilight
    // 4.61%), flight 2.13% (8.50%), 18 views 44.75 / 35.16 dB. Bounds: the
    // single-atmosphere targets of at most 400 weights, held over the family.
    EXPECT_EQ(r.views.size(), 18u); // six views at 1, 2.83 and 8
    expect_small_network_targets(r);
}
