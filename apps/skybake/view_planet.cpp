// skybake view planet: the interactive planet viewer (GLFW window).
#include <cmath>
#include <limits>
#include <optional>

#include "commands.h"
#include "flags.h"
#include "gl_flags.h"
#include "sky_common.h"
#include "skybake/image.h"
#include "skybake/image_io.h"
#include "skybake/viewer.h"

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
        std::string exposure = "auto", screenshot;
        std::optional<double> pitch;
    };
    auto o = std::make_shared<Opts>();
    sub->add_option("--model", o->model.path, "Trained neural sky (weights JSON from `skybake sky train`)")->required();
    o->model.add_aerosol(*sub);
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
    sub->add_option("--yaw", o->v.yaw_deg,
                    "Starting heading, degrees from +x towards +y as --sun-azimuth-deg (positive turns left, "
                    "counter-clockwise seen from above; equal to the sun's azimuth: facing the sun)")
        ->check(real_in(-360.0, 360.0, "degrees"))
        ->capture_default_str();
    sub->add_option("--pitch", o->pitch,
                    "Starting angle above the horizontal, degrees: positive looks up, -90 straight down (default: "
                    "5 less 1.5 times the horizon's dip, so that from high up the view looks down at the planet)")
        ->check(real_in(-90.0, 90.0, "degrees"));
    sub->add_option("--exposure", o->exposure,
                    "Starting exposure in stops, or auto (from the first frame, as `skybake view MODEL`: its "
                    "95th-percentile luminance maps to 0.6)")
        ->check(auto_or_real_in(-64.0, 64.0, "stops"))
        ->capture_default_str();
    sub->add_option("--screenshot", o->screenshot,
                    "Render the starting view headless (EGL), no window, to this .png (tone-mapped) or .exr "
                    "(linear, times 2^exposure)");
    sub->add_option("--frames", o->v.frames, "Close after N frames (0: run until closed)")
        ->check(integer_in(0, 100000000))
        ->capture_default_str();
    sub->add_option("--screenshot-path", o->v.screenshot, "Where the P key writes a PNG")->capture_default_str();
    sub->add_option("--sky", o->sky, "network, or reference (the seed's sum in GLSL)")->capture_default_str();
    sub->add_option("--ground", o->ground, "Ground model: lambert (physical) or as-published (the paper's b-scaled term; also: seed)")
        ->capture_default_str();
    o->gl.add(*sub, true);
    sub->callback([o, sub] {
        parse_flag("--size", [&] { parse_size(o->size, o->v.width, o->v.height, "--size"); });
        if (o->sky != "network" && o->sky != "reference")
            throw UsageError("unknown sky '" + o->sky + "'; use network or reference", "--sky");
        o->v.render = o->gl.options(o->sky == "network" ? PlanetSky::Network : PlanetSky::Reference);
        if (o->ground != "lambert" && o->ground != "as-published" && o->ground != "seed")
            throw UsageError("unknown ground model '" + o->ground + "'; use lambert or as-published", "--ground");
        o->v.render.published_ground = o->ground != "lambert";
        o->v.auto_exposure = o->exposure == "auto";
        o->v.exposure_ev = o->v.auto_exposure ? 0.0 : std::stod(o->exposure);
        o->v.pitch_deg = o->pitch ? *o->pitch : std::numeric_limits<double>::quiet_NaN();
        if (!o->screenshot.empty()) {
            check_output_path(o->screenshot, {".png", ".exr"}, "--screenshot");
            if (sub->count("--frames") > 0)
                throw UsageError("--frames is for the window; --screenshot draws the starting view once", "--frames");
        }
        const NeuralSky net = o->model.load_weights();
        const SkyModel model = neural_reference_model(net);
        if (o->screenshot.empty()) {
            run_planet_viewer(model, &net, o->v);
            return;
        }
        // Headless: the window's first frame (camera, shading, exposure) without the window.
        const ViewerOptions& v = o->v;
        const double R = model.atmosphere().planet_radius_km;
        const double pitch = std::isnan(v.pitch_deg) ? planet_viewer_default_pitch_deg(R, v.altitude_km) : v.pitch_deg;
        const PlanetView view = planet_viewer_view(glm::dvec3(0.0, 0.0, R + v.altitude_km), v.yaw_deg, pitch,
                                                   v.sun_azimuth_deg, v.sun_elevation_deg, v.width, v.height);
        PlanetRenderer renderer(model, &net, v.render);
        PlanetFrameStats st;
        Image img = renderer.render(view, &st);
        const float ev = v.auto_exposure ? model_auto_exposure_ev(img) : float(v.exposure_ev);
        if (lower_extension(o->screenshot) == ".exr") {
            const float k = std::exp2(ev);
            for (float& x : img.rgb)
                x *= k;
            save_image(o->screenshot, img);
        } else {
            save_image(o->screenshot, img, ToneMap{ev, ToneCurve::Aces});
        }
        info("{}x{} view from {} km (yaw {:.1f}, pitch {:.1f} deg), sun at {} deg: {} triangles in {:.3f} s at "
             "exposure {:+.2f} EV; wrote {}",
             v.width, v.height, v.altitude_km, v.yaw_deg, pitch, v.sun_elevation_deg, st.triangles,
             st.clod_seconds + st.draw_seconds, ev, o->screenshot);
    });
}

SKYBAKE_CLI_COMMAND("view", add_view_planet)

} // namespace skybake::cli
