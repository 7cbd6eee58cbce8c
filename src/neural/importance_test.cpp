// Importance sampling of the training set (NeuralTrainOptions::hard_share):
// the hard samples lie where they are meant to, are valid and deterministic,
// and replace the stated share of the uniform ones.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include <gtest/gtest.h>

#include "neural/internal.h"
#include "skybake/error.h"
#include "skybake/neural.h"

namespace skybake {
namespace {

using namespace neural;

constexpr double kPi = 3.14159265358979323846;

TEST(NeuralImportance, HardSamplesLieAtTheHorizonTheSunAndTheTerminator) {
    const Atmosphere atm = atmosphere_preset("earth");
    const std::vector<SkySample> s = draw_hard_samples(3000, 7, atm);
    ASSERT_EQ(s.size(), 3000u);
    const double R0 = atm.planet_radius_km;
    for (std::size_t i = 0; i < s.size(); ++i) {
        const SkySample& x = s[i];
        ASSERT_TRUE(is_valid_sky_sample(x, 1e-6)) << i;
        const double r = R0 + atm.altitude_from_density(x.density);
        const double mu_h = -std::sqrt(std::max(0.0, 1.0 - (R0 / r) * (R0 / r)));
        const double sun = std::asin(double(x.cos_sun_zenith));
        switch (i % 3) {
        case 0:
            // within sin 2° in cosine (the density's float rounding moves the horizon a little)
            EXPECT_LE(std::abs(double(x.cos_view_zenith) - mu_h), std::sin(2.0 * kPi / 180.0) + 1e-4) << i;
            EXPECT_GE(sun, -20.0 * kPi / 180.0 - 1e-5) << i;
            break;
        case 1:
            EXPECT_GE(x.cos_view_sun, std::cos(15.0 * kPi / 180.0) - 1e-6) << i;
            break;
        default:
            EXPECT_GE(sun, -15.0 * kPi / 180.0 - 1e-5) << i;
            EXPECT_LE(sun, 5.0 * kPi / 180.0 + 1e-5) << i;
        }
    }
    const std::vector<SkySample> again = draw_hard_samples(3000, 7, atm);
    for (std::size_t i = 0; i < s.size(); ++i)
        ASSERT_EQ(std::memcmp(&s[i], &again[i], sizeof(SkySample)), 0);
}

TEST(NeuralImportance, TheShareReplacesThatManyUniformSamples) {
    const SkyModel model(atmosphere_preset("earth"));
    NeuralTrainOptions o;
    o.inputs = InputEncoding::Horizon;
    o.outputs = OutputEncoding::Residual;
    o.max_n_samples = 2000;
    const NeuralEncoding enc = make_training_encoding(model, o);
    const TrainingData uniform = make_training_data(model, enc, 9000, 3, Device::Cpu);
    const TrainingData none = make_training_data(model, enc, 9000, 3, Device::Cpu, 0.0);
    EXPECT_EQ(uniform.x, none.x); // no share: the uniform set, bit for bit
    const TrainingData hard = make_training_data(model, enc, 9000, 3, Device::Cpu, 0.3);
    int changed = 0;
    for (Eigen::Index i = 0; i < hard.x.cols(); ++i)
        changed += hard.x.col(i) != uniform.x.col(i);
    EXPECT_EQ(changed, 2700);
    EXPECT_TRUE(hard.t.allFinite());
    // The option is checked.
    o.hard_share = 1.5;
    o.samples = 1000;
    o.batch = 100;
    o.heldout_samples = 100;
    try {
        train_neural_sky(model, o);
        FAIL();
    } catch (const Error& e) {
        EXPECT_EQ(e.where(), "hard_share");
    }
}

} // namespace
} // namespace skybake
