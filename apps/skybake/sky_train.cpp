// skybake sky train: fit the seed's perceptron (or a larger one) to the sky model.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "commands.h"
#include "core/parse_number.h"
#include "flags.h"
#include "skybake/files.h"
#include "sky_common.h"
#include "skybake/neural.h"

namespace skybake::cli {

void add_sky_train(CLI::App& group) {
    auto* sub = group.add_subcommand("train", "Train a neural sky (by default the best network of at most 400 weights; "
                                              "--topology paper --inputs seed --outputs radiance --brightness linear "
                                              "is the seed's)");
    struct Opts {
        AtmosphereFlags atm;
        NeuralTrainOptions t;
        // The defaults: the best network of at most 400 weights (docs/neural.md, "Size and accuracy").
        std::string topology = kDefaultTopology, inputs = "horizon", outputs = "phase-factored", brightness = "log";
        std::string output, curve, chart, device = "cpu", aerosol_range, aerosol_component = "mie", multiple_term = "march";
        double log_range_decades = 6.0;
        int steps = kTrainingTargetSteps;
        bool json = false;
    };
    auto o = std::make_shared<Opts>();
    o->atm.add(*sub);
    sub->add_option("--samples", o->t.samples, "Training samples")
        ->check(integer_in(16, 2'147'483'647))
        ->capture_default_str();
    sub->add_option("--topology", o->topology,
                    "paper (4 x 4-8-4-1, 324 weights), independent:W1xW2... or shared:W1xW2...")
        ->capture_default_str();
    sub->add_option("--inputs", o->inputs,
                    "Network inputs: horizon (view ray length split at the horizon, altitude coordinate) or seed "
                    "(the four cosines and density as they are)")
        ->capture_default_str();
    sub->add_option("--outputs", o->outputs,
                    "Network outputs: residual (corrections of an analytic few-step march, per component, and the "
                    "multiply scattered light when there is some), phase-factored (in-scatter per component, exact "
                    "phase functions outside; single scattering) or radiance (R/N, G/N, B/N and brightness, as in "
                    "the seed); default residual");
    sub->add_option("--brightness", o->brightness,
                    "Brightness output M: log (relative accuracy) or linear (as printed; also: seed)")
        ->capture_default_str();
    sub->add_option("--log-range", o->log_range_decades, "Decades of N/max{N} the log brightness covers")
        ->check(real_in(0.0, 80.0, "decades", End::Open))
        ->capture_default_str();
    sub->add_option("--epochs", o->t.adam_epochs,
                    "Adam epochs (default: the size's measured schedule, 60 up to 32 wide, 150 up to 64, 30 wider)")
        ->check(integer_in(0, 100'000));
    sub->add_option("--lm-iterations", o->t.lm_iterations,
                    "Levenberg-Marquardt iterations after Adam (default: 20 up to 16 wide, 3 up to 32, else 0)")
        ->check(integer_in(0, 10'000));
    sub->add_option("--lm-samples", o->t.lm_samples, "Samples in the LM least squares (0: automatic)")
        ->check(integer_in(0, 100'000'000))
        ->capture_default_str();
    sub->add_option("--batch", o->t.batch, "Adam mini-batch, in samples (default 1024, or --samples if fewer)")
        ->check(integer_in(1, 100'000'000));
    sub->add_option("--learning-rate", o->t.learning_rate,
                    "Adam step size of the first epoch (default: 0.02 up to 32 wide, 0.01 up to 64, 0.005 wider)")
        ->check(real_in(0.0, 10.0, "", End::Open));
    sub->add_option("--learning-rate-final", o->t.learning_rate_final, "Adam step size of the last epoch")
        ->check(real_in(0.0, 10.0, "", End::Open))
        ->capture_default_str();
    sub->add_option("--heldout", o->t.heldout_samples, "Held-out samples for the learning curve")
        ->check(integer_in(1, 100'000'000))
        ->capture_default_str();
    sub->add_option("--seed", o->t.seed, "Random seed")->check(integer_in(0, INT64_MAX))->capture_default_str();
    sub->add_option("--steps", o->steps, "Steps of the sky model's sum for the targets")
        ->check(integer_in(1, 4096))
        ->capture_default_str();
    sub->add_option("--device", o->device, "Where the training targets are computed: cpu or cuda")
        ->capture_default_str();
    sub->add_option("--curve", o->curve, "Write the learning curve as CSV");
    sub->add_option("--chart", o->chart, "Write the learning curve as a PNG chart");
    sub->add_option("--aerosol-range", o->aerosol_range,
                    "MIN:MAX: train one network for a family of atmospheres whose aerosol amount, a multiple of the "
                    "atmosphere's, is an input chosen at run time (sky eval/render --aerosol)");
    sub->add_option("--hard-share", o->t.hard_share,
                    "Share of the training samples drawn near the horizon, the sun and the terminator instead of "
                    "uniformly (importance sampling)")
        ->check(real_in(0.0, 1.0, ""))
        ->capture_default_str();
    sub->add_option("--flight-share", o->t.flight_share,
                    "Share of the training samples drawn as a flight's (altitude uniform to 60 km, the sun down to "
                    "-20 degrees) instead of uniformly (default: 0.4 with multiple scattering, else 0)")
        ->check(real_in(0.0, 1.0, ""));
    sub->add_option("--multiple-term", o->multiple_term,
                    "With --scattering multiple and residual outputs, the multiply scattered light: march (a "
                    "correction of an isotropic march of the sky's mean radiance) or log (log-encoded over 12 decades)")
        ->capture_default_str();
    sub->add_option("--aerosol-component", o->aerosol_component,
                    "With --aerosol-range: the scattering component whose amount varies")
        ->capture_default_str();
    sub->add_option("-o,--output", o->output, "Weights file (JSON)")->required();
    add_json_flag(*sub, o->json);
    sub->callback([o, sub] {
        check_output_path(o->output, {".json"}, "--output");
        if (!o->curve.empty())
            check_output_path(o->curve, {".csv"}, "--curve");
        if (!o->chart.empty())
            check_output_path(o->chart, {".png"}, "--chart");
        for (const std::string* p : {&o->curve, &o->chart})
            if (!p->empty() && *p == o->output)
                throw UsageError("the curve and chart files must differ from the weights file", *p);
        o->t.device = parse_flag("--device", [&] { return parse_device(o->device); });
        if (o->t.device == Device::Cuda)
            require_cuda_device("--device cuda");
        Atmosphere atm = o->atm.load(*sub);
        // Targets good enough to learn from: the refined shell rule unless
        // --table-rule says otherwise (docs/neural.md, "Training targets").
        if (!given(*sub, "--table-rule"))
            atm.table_rule = TableRule::Refined;
        o->t.topology = parse_flag("--topology", [&] { return parse_topology(o->topology); });
        { // the schedule measured for the network's size, for what is not asked for
            const NeuralSchedule schedule = training_schedule(o->t.topology);
            if (!given(*sub, "--epochs"))
                o->t.adam_epochs = schedule.adam_epochs;
            if (!given(*sub, "--learning-rate"))
                o->t.learning_rate = schedule.learning_rate;
            if (!given(*sub, "--lm-iterations"))
                o->t.lm_iterations = schedule.lm_iterations;
        }
        o->t.brightness = parse_flag("--brightness", [&] { return parse_brightness_encoding(o->brightness); });
        o->t.inputs = parse_flag("--inputs", [&] { return parse_input_encoding(o->inputs); });
        if (given(*sub, "--outputs")) {
            o->t.outputs = parse_flag("--outputs", [&] { return parse_output_encoding(o->outputs); });
            if (o->t.outputs == OutputEncoding::PhaseFactored && atm.scattering != Scattering::Single)
                throw UsageError("phase-factored outputs are for single scattering only; use --outputs residual or "
                                 "radiance with multiple scattering",
                                 "--outputs");
        } else
            o->t.outputs = default_output_encoding(atm);
        o->t.log_range = o->log_range_decades * std::log(10.0);
        if (given(*sub, "--multiple-term") &&
            (atm.scattering == Scattering::Single || o->t.outputs != OutputEncoding::Residual))
            throw UsageError("the multiple-scattering term is for residual outputs with --scattering multiple",
                             "--multiple-term");
        if (o->multiple_term != "march" && o->multiple_term != "log")
            throw UsageError(fmt::format("'{}' is not march or log", o->multiple_term), "--multiple-term");
        o->t.multiple_march = o->multiple_term == "march";
        if (!o->aerosol_range.empty()) {
            const std::string_view range = o->aerosol_range;
            const std::size_t colon = range.find(':');
            double lo = 0.0, hi = 0.0;
            if (colon == std::string_view::npos || !parse_decimal(range.substr(0, colon), lo) ||
                !parse_decimal(range.substr(colon + 1), hi))
                throw UsageError(fmt::format("'{}' is not MIN:MAX (e.g. 1:32)", range), "--aerosol-range");
            o->t.family_component = o->aerosol_component;
            o->t.aerosol_min = lo;
            o->t.aerosol_max = hi;
        } else {
            refuse_if_given(*sub, "--aerosol-component", "without --aerosol-range");
        }
        if (!given(*sub, "--batch"))
            o->t.batch = std::min<std::size_t>(o->t.batch, o->t.samples);
        else if (o->t.batch > o->t.samples)
            throw UsageError(fmt::format("the mini-batch of {} samples is larger than --samples {}", o->t.batch,
                                         o->t.samples),
                             "--batch");
        SkyModelOptions opts;
        opts.steps = o->steps;
        opts.tables = kTrainingTargetTables;
        const SkyModel model(atm, opts);
        std::vector<LearningCurvePoint> curve;
        const NeuralSky net = [&] {
            try {
                return train_neural_sky(model, o->t, &curve);
            } catch (const Error& e) {
                if (e.where() == "family_component") // the family the flags ask for cannot be trained
                    throw UsageError(e.message(), "--aerosol-range");
                throw;
            }
        }();
        OutputSet files; // all three, or none
        save_neural_sky(files.stage(o->output), net);
        if (!o->curve.empty())
            save_learning_curve_csv(files.stage(o->curve), curve);
        if (!o->chart.empty())
            save_learning_curve_png(files.stage(o->chart), curve,
                                    fmt::format("{} on {}, {} samples", net.topology.name(), atm.name, o->t.samples));
        files.commit();
        const NeuralTrainingSummary& s = net.training;
        // What the network learns: with multiple scattering, the total radiance
        // (single + multiple, as SkyModel gives it), not a residual.
        const std::string target =
            atm.scattering == Scattering::Multiple
                ? fmt::format("total radiance, single + multiple ({})", multiple_scattering_method_name(atm.multiple_method))
                : std::string("single-scattered radiance");
        const std::string family =
            net.encoding.has_family() ? fmt::format(", {} amount {:g} to {:g}", net.encoding.family_component,
                                                    net.encoding.aerosol_min, net.encoding.aerosol_max)
                                      : std::string();
        info("trained {} ({} weights) on {} samples of '{}'{} ({}) in {:.1f} s ({} threads): held-out RMS {:.4g}, "
             "mean relative error {:.3g}% -> {}",
             net.topology.name(), net.topology.weight_count(), s.samples, atm.name, family, target, s.seconds, s.threads,
             s.heldout_rms, 100.0 * s.heldout_mean_relative, o->output);
        // A network whose outputs all died (too large a first step for its
        // width: 0.02 for shared:128x128) is saved, but said plainly. Dead
        // residual outputs scale the analytic march by a constant e^(±4.4):
        // the march alone is within about 10% (docs/neural.md), so a residual
        // network at 50% has made it worse.
        const double dead = net.encoding.outputs == OutputEncoding::Residual ? 0.5 : 0.99;
        if (s.heldout_mean_relative >= dead)
            info("warning: the network did not learn (held-out mean relative error {:.3g}%); wide networks want a "
                 "smaller --learning-rate (0.005 for 128 wide)",
                 100.0 * s.heldout_mean_relative);
        if (o->json)
            print_json({{"atmosphere", atm.name},
                        {"target", target},
                        {"topology", net.topology.name()},
                        {"weights", net.topology.weight_count()},
                        {"brightness", o->brightness},
                        {"inputs", input_encoding_name(net.encoding.inputs)},
                        {"outputs", output_encoding_name(net.encoding.outputs)},
                        {"aerosol_range", net.encoding.has_family()
                                              ? nlohmann::json{net.encoding.aerosol_min, net.encoding.aerosol_max}
                                              : nlohmann::json(nullptr)},
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
                        {"curve", o->curve.empty() ? nlohmann::json(nullptr) : nlohmann::json(o->curve)},
                        {"chart", o->chart.empty() ? nlohmann::json(nullptr) : nlohmann::json(o->chart)}});
    });
}

SKYBAKE_CLI_COMMAND("sky", add_sky_train)

} // namespace skybake::cli
