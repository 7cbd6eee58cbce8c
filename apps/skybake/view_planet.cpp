// skybake view planet: the interactive planet viewer (GLFW window).
#include "commands.h"
#include "flags.h"
#include "gl_flags.h"
#include "sky_common.h"

namespace skybake::cli {

void add_view_planet(CLI::App& group) {
    auto* sub = group.add_subcommand("planet", "Fly around the planet in a window: drag to look, W/A/S/D/R/F to "
                                               "move (speed follows the altitude, Shift x10), arrows move the sun, "
                                               "V per-vertex/per-pixel, +/- exposure, P screenshot, Esc quits");
    struct Opts {
        ModelFlag model;
        ViewerOptions v;
        std::string size = "1280x1024", sky = "network";
        GlRenderFlags gl;
        std::string ground = "lambert";
    };
    auto o = std::make_shared<Opts>();
    sub->add_option("--model", o->model.path, "Trained neural sky (weights JSON from `skybake sky train`)")->required();
    sub->add_option("--size", o->size, "Window size WxH in pixels")->capture_default_str();
    sub->add_option("--altitude-km", o->v.altitude_km, "Starting altitude, km")
        ->check(real_in(0.0001, 1e6, "km"))
        ->capture_default_str();
    sub->add_option("--sun-elevation-deg", o->v.sun_elevation_deg, "Starting sun elevation")
        ->check(real_in(-90.0, 90.0, "degrees"))
        ->capture_default_str();
    sub->add_option("--sun-azimuth-deg", o->v.sun_azimuth_deg, "Starting sun azimuth")
        ->check(real_in(-360.0, 360.0, "degrees"))
        ->capture_default_str();
    sub->add_option("--exposure", o->v.exposure_ev, "Starting exposure, stops")
        ->check(real_in(-64.0, 64.0, "stops"))
        ->capture_default_str();
    sub->add_option("--frames", o->v.frames, "Close after N frames (0: run until closed)")
        ->check(integer_in(0, 100000000))
        ->capture_default_str();
    sub->add_option("--screenshot-path", o->v.screenshot, "Where the P key writes a PNG")->capture_default_str();
    sub->add_option("--sky", o->sky, "network, or reference (the seed's sum in GLSL)")->capture_default_str();
    sub->add_option("--ground", o->ground, "Ground model: lambert (physical) or as-published (the paper's b-scaled term; also: seed)")
        ->capture_default_str();
    o->gl.add(*sub, true);
    sub->callback([o] {
        parse_flag("--size", [&] { parse_size(o->size, o->v.width, o->v.height, "--size"); });
        if (o->sky != "network" && o->sky != "reference")
            throw UsageError("unknown sky '" + o->sky + "'; use network or reference", "--sky");
        o->v.render = o->gl.options(o->sky == "network" ? PlanetSky::Network : PlanetSky::Reference);
        if (o->ground != "lambert" && o->ground != "as-published" && o->ground != "seed")
            throw UsageError("unknown ground model '" + o->ground + "'; use lambert or as-published", "--ground");
        o->v.render.published_ground = o->ground != "lambert";
        const NeuralSky net = load_neural_sky(o->model.path);
        const SkyModel model = neural_reference_model(net);
        run_planet_viewer(model, &net, o->v);
    });
}

SKYBAKE_CLI_COMMAND("view", add_view_planet)

} // namespace skybake::cli
