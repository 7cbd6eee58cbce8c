// Tests of the aerosol family: a network whose aerosol amount is a fifth
// input. Its targets against the sky model of the scaled atmosphere, its
// analytic march against a march built for that atmosphere, the weights file,
// and the checks on its range.
#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "neural/error_bound_test_util.h"
#include "neural/internal.h"
#include "neural/mlp_hd.h"
#include "sky/device.h"
#include "skybake/error.h"
#include "skybake/neural.h"

namespace skybake {
namespace {

using namespace neural;

NeuralEncoding family_encoding(const SkyModel& model, double lo, double hi) {
    NeuralTrainOptions o;
    o.inputs = InputEncoding::Horizon;
    o.outputs = OutputEncoding::Residual;
    o.max_n_samples = 2000;
    o.family_component = "mie";
    o.aerosol_min = lo;
    o.aerosol_max = hi;
    return make_training_encoding(model, o);
}

double relative(const glm::vec3& a, const glm::vec3& ref) {
    const double n = glm::length(glm::dvec3(ref));
    return n > 0.0 ? glm::length(glm::dvec3(a) - glm::dvec3(ref)) / n : glm::length(glm::dvec3(a));
}

// The targets scale the aerosol inside the table path, per sample; the sky
// model of the scaled atmosphere computes the same light through its own path
// (every component's sum with its phase function, no split).
TEST(NeuralFamily, TargetsAreTheSkyOfTheScaledAtmosphere) {
    const SkyModel model(atmosphere_preset("earth"));
    const NeuralEncoding enc = family_encoding(model, 0.5, 20.0);
    const std::vector<SkySample> s = draw_sky_samples(3000, 21);
    for (double k : {0.5, 1.0, 3.3, 20.0}) {
        const std::vector<float> amount(s.size(), float(k));
        std::vector<glm::vec3> split, scaled;
        scaled_sky_targets(model, s, amount, family_component_index(enc, model.atmosphere()), split, scaled);
        const SkyModel direct(scaled_atmosphere(enc, model.atmosphere(), double(float(k))), model.options());
        std::vector<glm::vec3> ref(s.size());
        evaluate_sky(direct, s, ref, SkyMethod::Tables);
        double worst = 0.0;
        int lit = 0;
        for (std::size_t i = 0; i < s.size(); ++i) {
            if (glm::length(ref[i]) > 0.0f)
                ++lit;
            worst = std::max(worst, relative(scaled[i], ref[i]));
        }
        EXPECT_GT(lit, 1000);
        EXPECT_LT(worst, 2e-5) << "aerosol " << k;
    }
    // And the amount matters: 20 times the aerosol is another sky.
    std::vector<glm::vec3> split, one, twenty;
    scaled_sky_targets(model, s, std::vector<float>(s.size(), 1.0f), 1, split, one);
    scaled_sky_targets(model, s, std::vector<float>(s.size(), 20.0f), 1, split, twenty);
    double mean = 0.0;
    int lit = 0;
    for (std::size_t i = 0; i < s.size(); ++i)
        if (glm::length(one[i]) > 0.0f) {
            mean += relative(twenty[i], one[i]);
            ++lit;
        }
    mean /= double(lit);
    std::printf("20 times the aerosol: mean relative change %.3f over %d lit samples\n", mean, lit);
    EXPECT_GT(mean, 0.1);
}

// The march of a family at amount k equals the march of a family whose
// atmosphere has k times the aerosol (its coefficients set directly), at 1.
TEST(NeuralFamily, TheAnalyticMarchScalesTheAerosol) {
    const SkyModel model(atmosphere_preset("earth"));
    const NeuralEncoding enc = family_encoding(model, 0.25, 16.0);
    MlpHD family;
    set_encoding_hd(enc, model.atmosphere(), family);
    ASSERT_EQ(family.family, 1);
    const std::vector<SkySample> s = draw_sky_samples(2000, 5);
    for (float k : {0.25f, 1.0f, 7.0f, 16.0f}) {
        family.aerosol = k;
        MlpHD direct;
        set_encoding_hd(enc, scaled_atmosphere(enc, model.atmosphere(), double(k)), direct);
        direct.aerosol = 1.0f;
        double worst = 0.0;
        for (const SkySample& x : s) {
            float a[kMaxOutputs], b[kMaxOutputs];
            analytic_terms(family, x.cos_view_zenith, x.cos_view_sun, x.cos_sun_zenith, x.density, a);
            analytic_terms(direct, x.cos_view_zenith, x.cos_view_sun, x.cos_sun_zenith, x.density, b);
            for (int i = 0; i < 3 * family.terms; ++i)
                worst = std::max(worst, double(std::abs(a[i] - b[i])) / std::max(1e-30, double(std::abs(b[i]))));
        }
        EXPECT_LT(worst, 2e-5) << "aerosol " << k; // k β rounded once against β·k in float
    }
    // The fifth input runs from −1 to 1 over the range, log-uniformly.
    float in[kMaxInputs];
    for (auto [k, want] : {std::pair{0.25f, -1.0f}, {2.0f, 0.0f}, {16.0f, 1.0f}}) {
        family.aerosol = k;
        encode_inputs(family, 0.3f, 0.2f, 0.5f, 0.7f, in);
        EXPECT_NEAR(in[4], want, 1e-6f) << k;
    }
}

// A hazy member puts optical depths of tens on a grazing ray near the ground.
// The family's march takes the view's depth from Chapman integrals and
// follows the sky there; the trapezoids of the single-atmosphere march miss
// it by orders of magnitude, more than the network's e^±2 can correct.
TEST(NeuralFamily, TheMarchFollowsAHazySky) {
    const SkyModel model(atmosphere_preset("earth"));
    const NeuralEncoding enc = family_encoding(model, 1.0, 32.0);
    NeuralEncoding plain = enc;
    plain.family_component.clear();
    const std::vector<SkySample> s = draw_sky_samples(4000, 17);
    const float K = 32.0f;
    const std::vector<float> amount(s.size(), K);
    std::vector<glm::vec3> split, ref;
    scaled_sky_targets(model, s, amount, family_component_index(enc, model.atmosphere()), split, ref);
    const Atmosphere hazy = scaled_atmosphere(enc, model.atmosphere(), double(K));
    MlpHD family, trapezoid;
    set_encoding_hd(enc, model.atmosphere(), family);
    family.aerosol = K;
    set_encoding_hd(plain, hazy, trapezoid);
    auto march = [&](const MlpHD& m, const SkySample& x) {
        float base[kMaxOutputs];
        analytic_terms(m, x.cos_view_zenith, x.cos_view_sun, x.cos_sun_zenith, x.density, base);
        glm::vec3 c(0.0f);
        for (int k = 0; k < m.terms; ++k) {
            const float p = sky::phase_value(m.term_phase[k], m.term_g[k], x.cos_view_sun);
            c += p * glm::vec3(base[3 * k], base[3 * k + 1], base[3 * k + 2]);
        }
        return c;
    };
    std::vector<double> ef, et;
    for (std::size_t i = 0; i < s.size(); ++i)
        if (glm::length(ref[i]) > 1e-6f * glm::length(glm::vec3(0.1f))) {
            // |ln| of the ratio per channel, the residual's own measure
            double f = 0.0, t = 0.0;
            const glm::vec3 a = march(family, s[i]), b = march(trapezoid, s[i]);
            for (int c = 0; c < 3; ++c) {
                f = std::max(f, std::abs(std::log(std::max(1e-30, double(a[c])) / double(ref[i][c]))));
                t = std::max(t, std::abs(std::log(std::max(1e-30, double(b[c])) / double(ref[i][c]))));
            }
            ef.push_back(f);
            et.push_back(t);
        }
    // Beyond e^±2 the network's outputs (kResidualRange) cannot correct the march.
    auto beyond = [](const std::vector<double>& e) {
        return double(std::count_if(e.begin(), e.end(), [](double v) { return v > double(kResidualRange); })) /
               double(e.size());
    };
    const double fb = beyond(ef), tb = beyond(et);
    const ErrorStats f = error_stats(ef), t = error_stats(et);
    std::printf("march at 32x the aerosol, |ln(A/S)| over %zu lit samples: Chapman view p50 %.3f p99 %.3f, %.2f%% "
                "beyond e^2; trapezoids p50 %.3f p99 %.3f, %.2f%% beyond\n",
                f.count, f.p50, f.p99, 100.0 * fb, t.p50, t.p99, 100.0 * tb);
    // (At 1x, the single atmosphere's march, which the default network
    // corrects, has p99 1.21 and none beyond.)
    EXPECT_LT(f.p99, 1.6);
    EXPECT_LT(fb, 0.01);
    EXPECT_GT(t.p99, 2.0);
    EXPECT_GT(tb, 3.0 * fb);
}

// Training data of a family: every input, target and base finite, the amounts
// log-uniform over the range, the same for the same seed.
TEST(NeuralFamily, TrainingDataIsFiniteAndSpansTheRange) {
    const SkyModel model(atmosphere_preset("earth"));
    const NeuralEncoding enc = family_encoding(model, 1.0, 32.0);
    const TrainingData d = make_training_data(model, enc, 20000, 9, Device::Cpu);
    ASSERT_EQ(d.x.rows(), 5);
    EXPECT_TRUE(d.x.allFinite());
    EXPECT_TRUE(d.t.allFinite());
    EXPECT_TRUE(d.base.allFinite());
    for (const glm::vec3& r : d.radiance)
        ASSERT_TRUE(std::isfinite(r.x) && std::isfinite(r.y) && std::isfinite(r.z));
    ASSERT_EQ(d.aerosol.size(), 20000u);
    const auto [lo, hi] = std::minmax_element(d.aerosol.begin(), d.aerosol.end());
    EXPECT_GE(*lo, 1.0f);
    EXPECT_LE(*hi, 32.0f);
    EXPECT_LT(*lo, 1.01f);
    EXPECT_GT(*hi, 31.5f);
    // log-uniform: the geometric middle of the range splits the amounts in half
    const auto below = std::count_if(d.aerosol.begin(), d.aerosol.end(), [](float a) { return a < std::sqrt(32.0f); });
    EXPECT_NEAR(double(below) / 20000.0, 0.5, 0.02);
    EXPECT_EQ(draw_aerosol(enc, 100, 9), std::vector<float>(d.aerosol.begin(), d.aerosol.begin() + 100));
}

TEST(NeuralFamily, TheWeightsFileKeepsTheFamilyAndChecksTheAmount) {
    NeuralSky net = neural_test::with_family(
        neural_test::with_encoding(neural_test::random_network("shared:8x6", 3), InputEncoding::Horizon,
                                   OutputEncoding::Residual, 4),
        0.5, 8.0, 1.0, 5);
    EXPECT_EQ(net.topology.inputs, 5);
    EXPECT_EQ(net.topology.weight_count(), (5 + 1) * 8 + (8 + 1) * 6 + (6 + 1) * net.topology.outputs);
    const NeuralSky back = neural_sky_from_json(neural_sky_to_json(net));
    EXPECT_EQ(back.encoding.family_component, "mie");
    EXPECT_EQ(back.encoding.aerosol_min, 0.5);
    EXPECT_EQ(back.encoding.aerosol_max, 8.0);
    EXPECT_EQ(back.weights, net.weights);
    // The amount is a run-time setting: every evaluator follows it.
    const std::vector<SkySample> s = draw_sky_samples(500, 3);
    NeuralSky hazy = back;
    hazy.aerosol = 6.0;
    std::vector<glm::vec3> a(s.size()), b(s.size());
    evaluate_neural_sky(back, s, a);
    evaluate_neural_sky(hazy, s, b);
    int differ = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
        differ += relative(b[i], a[i]) > 1e-3;
        EXPECT_LT(relative(b[i], neural_sky_radiance(hazy, s[i])), 1e-5);
    }
    EXPECT_GT(differ, 100);
    // Outside the range, or a network without a family: refused, naming the field.
    hazy.aerosol = 9.0;
    try {
        hazy.validate("net");
        FAIL() << "an amount outside the range was accepted";
    } catch (const Error& e) {
        EXPECT_EQ(e.where(), "net: aerosol");
    }
    NeuralSky plain = neural_test::random_network("paper", 1);
    plain.aerosol = 2.0;
    EXPECT_THROW(plain.validate(), Error);
    // A corrupt range or component in the file: one error naming the field.
    const nlohmann::json text = nlohmann::json::parse(neural_sky_to_json(net));
    for (const nlohmann::json& bad : {nlohmann::json{8.0, 0.5}, nlohmann::json{0.0, 8.0}, nlohmann::json{1.0}}) {
        nlohmann::json t = text;
        t["encoding"]["family"]["aerosol_range"] = bad;
        try {
            (void)neural_sky_from_json(t.dump(), "w.json");
            FAIL() << bad << " was accepted";
        } catch (const Error& e) {
            EXPECT_NE(e.where().find("encoding.family"), std::string::npos) << e.where();
        }
    }
    nlohmann::json t = text;
    t["encoding"]["family"]["component"] = "dust";
    EXPECT_THROW((void)neural_sky_from_json(t.dump(), "w.json"), Error);
    t = text; // the fifth input's weights without the family: the weight count no longer matches
    t["encoding"].erase("family");
    EXPECT_THROW((void)neural_sky_from_json(t.dump(), "w.json"), Error);
}

TEST(NeuralFamily, OnlyResidualOutputsOfSingleScatteringCarryOne) {
    const SkyModel model(atmosphere_preset("earth"));
    NeuralTrainOptions o;
    o.inputs = InputEncoding::Horizon;
    o.outputs = OutputEncoding::PhaseFactored;
    o.max_n_samples = 500;
    o.family_component = "mie";
    o.aerosol_min = 1.0;
    o.aerosol_max = 4.0;
    EXPECT_THROW(make_training_encoding(model, o), Error);
    o.outputs = OutputEncoding::Residual;
    o.family_component = "ozone"; // absorbs only: no phase term
    EXPECT_THROW(make_training_encoding(model, o), Error);
    o.family_component = "mie";
    o.aerosol_max = 1.0;
    try {
        make_training_encoding(model, o);
        FAIL();
    } catch (const Error& e) {
        EXPECT_EQ(e.where(), "family_component");
    }
}

} // namespace
} // namespace skybake
