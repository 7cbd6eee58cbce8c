// skybake sky error: accuracy of a trained neural sky against its sky model.
#include <cstdint>
#include <filesystem>
#include <optional>

#include "cli.h"
#include "commands.h"
#include "flags.h"
#include "skybake/neural.h"

namespace skybake::cli {

namespace {

nlohmann::json stats_json(const ErrorStats& s) {
    return {{"count", s.count}, {"mean", s.mean}, {"p50", s.p50}, {"p95", s.p95}, {"p99", s.p99}, {"max", s.max}};
}

} // namespace

void add_sky_error(CLI::App& group) {
    auto* sub = group.add_subcommand("error", "Measure a neural sky against the sky model: relative error, view PSNR");
    struct Opts {
        std::string model, size = "240x160", views_dir;
        NeuralErrorOptions e;
        bool no_views = false, json = false;
    };
    auto o = std::make_shared<Opts>();
    sub->add_option("--model", o->model, "Weights file (JSON from `skybake sky train`)")->required();
    sub->add_option("--samples", o->e.samples, "Held-out random valid samples")
        ->check(integer_in(1, 100'000'000))
        ->capture_default_str();
    sub->add_option("--seed", o->e.seed, "Seed of the held-out samples (default: a stream not used in training)")
        ->check(integer_in(0, INT64_MAX));
    sub->add_option("--flight-samples", o->e.flight_samples,
                    "Samples of a flight to space: altitude uniform in 0-60 km, the sun down to -20 degrees, any view "
                    "(0: none)")
        ->check(integer_in(0, 100'000'000))
        ->capture_default_str();
    sub->add_flag("--no-views", o->no_views, "Skip the PSNR of the seed's views");
    sub->add_option("--size", o->size, "Size of the rendered views WxH")->capture_default_str();
    sub->add_option("--views-dir", o->views_dir, "Also write the reference and neural views there as PNG (a "
                                                 "folder, created if missing)");
    add_json_flag(*sub, o->json);
    sub->callback([o, sub] {
        if (o->no_views)
            for (const char* f : {"--size", "--views-dir"})
                refuse_if_given(*sub, f, "with --no-views");
        parse_flag("--size", [&] { parse_size(o->size, o->e.view_width, o->e.view_height, "--size"); });
        std::optional<OutputFolder> views_folder; // an existing folder, or a new one in an existing folder
        if (!o->views_dir.empty())
            views_folder.emplace(o->views_dir, "--views-dir");
        o->e.views = !o->no_views;
        o->e.views_dir = o->views_dir;
        const NeuralSky net = load_neural_sky(o->model);
        const NeuralErrorReport r = measure_neural_sky_error(net, o->e);
        if (views_folder)
            views_folder->keep();
        if (o->json) {
            nlohmann::json views = nlohmann::json::array();
            for (const ViewPsnr& v : r.views)
                views.push_back({{"name", v.name}, {"psnr_db", v.psnr_db}});
            nlohmann::json j = {{"model", o->model},
                                {"topology", net.topology.name()},
                                {"weights", net.topology.weight_count()},
                                {"atmosphere", net.atmosphere.name},
                                {"aerosol_range", net.encoding.has_family()
                                                      ? nlohmann::json{net.encoding.aerosol_min, net.encoding.aerosol_max}
                                                      : nlohmann::json(nullptr)},
                                {"samples", o->e.samples},
                                {"relative_error", {{"all", stats_json(r.all)},
                                                    {"day", stats_json(r.day)},
                                                    {"twilight", stats_json(r.twilight)}}},
                                {"night_absolute_error_over_max_n", stats_json(r.night)},
                                {"views", views}};
            if (o->e.flight_samples > 0)
                j["flight"] = {{"samples", o->e.flight_samples},
                               {"max_altitude_km", o->e.flight.max_altitude_km},
                               {"min_sun_elevation_deg", o->e.flight.min_sun_elevation_deg},
                               {"relative_error", {{"all", stats_json(r.flight_all)},
                                                   {"day", stats_json(r.flight_day)},
                                                   {"twilight", stats_json(r.flight_twilight)}}},
                               {"night_absolute_error_over_max_n", stats_json(r.flight_night)}};
            if (!r.views.empty()) {
                j["mean_view_psnr_db"] = r.mean_view_psnr_db;
                j["min_view_psnr_db"] = r.min_view_psnr_db;
            }
            print_json(j);
            return;
        }
        const std::string family =
            net.encoding.has_family() ? fmt::format(" with {} amounts {:g} to {:g} (log-uniform)",
                                                    net.encoding.family_component, net.encoding.aerosol_min,
                                                    net.encoding.aerosol_max)
                                      : std::string();
        std::string t = fmt::format("{} ({} weights) on '{}'{}, {} held-out samples\n", net.topology.name(),
                                    net.topology.weight_count(), net.atmosphere.name, family, o->e.samples);
        t += "relative RGB error |dI|/|I|   count      mean      p50       p95       p99       max\n";
        auto row = [&](const char* name, const ErrorStats& s) {
            t += fmt::format("{:<28} {:>6}  {:>8.3f}% {:>8.3f}% {:>8.3f}% {:>8.3f}% {:>8.2f}%\n", name, s.count,
                             100 * s.mean, 100 * s.p50, 100 * s.p95, 100 * s.p99, 100 * s.max);
        };
        row("all (N > 0)", r.all);
        row("day (sun above horizon)", r.day);
        row("twilight (sun below, N > 0)", r.twilight);
        t += fmt::format("night (N = 0): {} samples, |dI|/max N mean {:.2e}, max {:.2e}\n", r.night.count,
                         r.night.mean, r.night.max);
        if (o->e.flight_samples > 0) {
            t += fmt::format("flight: {} samples, altitude 0 to {:g} km, sun down to {:g} deg\n", o->e.flight_samples,
                             o->e.flight.max_altitude_km, o->e.flight.min_sun_elevation_deg);
            row("flight, all (N > 0)", r.flight_all);
            row("flight, day", r.flight_day);
            row("flight, twilight", r.flight_twilight);
        }
        for (const ViewPsnr& v : r.views)
            t += fmt::format("view {:<14} PSNR {:6.2f} dB\n", v.name, v.psnr_db);
        if (!r.views.empty())
            t += fmt::format("views: mean PSNR {:.2f} dB, min {:.2f} dB\n", r.mean_view_psnr_db, r.min_view_psnr_db);
        std::fputs(t.c_str(), stdout);
    });
}

SKYBAKE_CLI_COMMAND("sky", add_sky_error)

} // namespace skybake::cli
