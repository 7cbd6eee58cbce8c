// skybake sky train: fit the seed's perceptron (or a larger one) to the sky model.
#include <cmath>

#include "commands.h"
#include "sky_common.h"
#include "skybake/neural.h"

namespace skybake::cli {

void add_sky_train(CLI::App& group) {
    auto* sub = group.add_subcommand("train", "Train a neural sky (the seed's 324-weight perceptron by default)");
    struct Opts {
        AtmosphereFlags atm;
        NeuralTrainOptions t;
        std::string topology = "paper", brightness = "log", output, curve, chart, device = "cpu";
        double log_range_decades = 6.0;
        int steps = 16;
        bool json = false;
    };
    auto o = std::make_shared<Opts>();
    o->atm.add(*sub);
    sub->add_option("--samples", o->t.samples, "Training samples (default 800000)");
    sub->add_option("--topology", o->topology,
                    "paper (4 x 4-8-4-1, 324 weights), independent:W1xW2... or shared:W1xW2... (default paper)");
    sub->add_option("--brightness", o->brightness,
                    "Brightness output M: log (default; relative accuracy) or seed (linear, as printed)");
    sub->add_option("--log-range", o->log_range_decades, "Decades of N/max{N} the log brightness covers (default 6)");
    sub->add_option("--epochs", o->t.adam_epochs, "Adam epochs (default 60)");
    sub->add_option("--lm-iterations", o->t.lm_iterations, "Levenberg-Marquardt iterations after Adam (default 30)");
    sub->add_option("--lm-samples", o->t.lm_samples, "Samples in the LM least squares (default: automatic)");
    sub->add_option("--batch", o->t.batch, "Adam mini-batch (default 1024)");
    sub->add_option("--learning-rate", o->t.learning_rate, "Adam step size of the first epoch (default 0.02)");
    sub->add_option("--learning-rate-final", o->t.learning_rate_final, "Adam step size of the last epoch (default 0.0005)");
    sub->add_option("--heldout", o->t.heldout_samples, "Held-out samples for the learning curve (default 20000)");
    sub->add_option("--seed", o->t.seed, "Random seed (default 1)");
    sub->add_option("--steps", o->steps, "Steps of the sky model's sum for the targets (default 16)");
    sub->add_option("--device", o->device, "Where the training targets are computed: cpu (default) or cuda");
    sub->add_option("--curve", o->curve, "Write the learning curve as CSV");
    sub->add_option("--chart", o->chart, "Write the learning curve as a PNG chart");
    sub->add_option("-o,--output", o->output, "Weights file (JSON)")->required();
    add_json_flag(*sub, o->json);
    sub->callback([o] {
        o->t.device = parse_device(o->device);
        if (o->t.device == Device::Cuda)
            require_cuda_device("--device cuda");
        const Atmosphere atm = o->atm.load();
        o->t.topology = parse_topology(o->topology);
        if (o->brightness == "log")
            o->t.brightness = BrightnessEncoding::Log;
        else if (o->brightness == "seed")
            o->t.brightness = BrightnessEncoding::Seed;
        else
            throw Error("unknown brightness encoding '" + o->brightness + "'; use log or seed", "--brightness");
        if (!(o->log_range_decades > 0.0 && o->log_range_decades <= 80.0))
            throw Error("the log range must be 0 to 80 decades", "--log-range");
        o->t.log_range = o->log_range_decades * std::log(10.0);
        for (const std::string* p : {&o->curve, &o->chart})
            if (!p->empty() && *p == o->output)
                throw Error("the curve and chart files must differ from the weights file", *p);
        if (!o->chart.empty() && std::filesystem::path(o->chart).extension() != ".png")
            throw Error("the chart must be a .png file", o->chart);
        SkyModelOptions opts;
        opts.steps = o->steps;
        const SkyModel model(atm, opts);
        std::vector<LearningCurvePoint> curve;
        const NeuralSky net = train_neural_sky(model, o->t, &curve);
        save_neural_sky(o->output, net);
        if (!o->curve.empty())
            save_learning_curve_csv(o->curve, curve);
        if (!o->chart.empty())
            save_learning_curve_png(o->chart, curve,
                                    fmt::format("{} on {}, {} samples", net.topology.name(), atm.name, o->t.samples));
        const NeuralTrainingSummary& s = net.training;
        info("trained {} ({} weights) on {} samples of '{}' in {:.1f} s ({} threads): held-out RMS {:.4g}, "
             "mean relative error {:.3g}% -> {}",
             net.topology.name(), net.topology.weight_count(), s.samples, atm.name, s.seconds, s.threads,
             s.heldout_rms, 100.0 * s.heldout_mean_relative, o->output);
        if (o->json)
            print_json({{"atmosphere", atm.name},
                        {"topology", net.topology.name()},
                        {"weights", net.topology.weight_count()},
                        {"brightness", o->brightness},
                        {"samples", s.samples},
                        {"adam_epochs", s.adam_epochs},
                        {"lm_iterations", s.lm_iterations},
                        {"seconds", s.seconds},
                        {"threads", s.threads},
                        {"max_n", net.encoding.max_n},
                        {"train_rms", s.train_rms},
                        {"heldout_rms", s.heldout_rms},
                        {"heldout_mean_relative", s.heldout_mean_relative},
                        {"output", o->output},
                        {"curve", o->curve},
                        {"chart", o->chart}});
    });
}

SKYBAKE_CLI_COMMAND("sky", add_sky_train)

} // namespace skybake::cli
