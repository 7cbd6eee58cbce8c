// skybake sky render: images of the sky, the ground and the planet.
#include <algorithm>
#include <chrono>
#include <cmath>

#include "commands.h"
#include "flags.h"
#include "gl_flags.h"
#include "sky_common.h"
#include "skybake/sky_source.h"
#include "skybake/image_io.h"

namespace skybake::cli {


void add_sky_render(CLI::App& group) {
    auto* sub = group.add_subcommand("render", "Render the sky, the ground and the planet (PNG or EXR)");
    struct Opts {
        AtmosphereFlags atm;
        ModelFlag model;
        SkyRenderSettings s;
        std::string view = "fisheye", size = "512x512", output, method = "tables", tone = "aces";
        std::string exposure = "auto";
        bool has_azimuth = false, no_sun = false, json = false;
        int steps = 16;
        std::string ground = "lambert";
        std::string device = "cpu";
        std::string renderer = "cpu";
        GlRenderFlags gl;
    };
    auto o = std::make_shared<Opts>();
    o->atm.add(*sub);
    o->model.add(*sub);
    sub->add_option("--altitude-km", o->s.altitude_km, "Observer altitude above the ground, km")
        ->check(real_in(0.0, 1e6, "km"))
        ->required();
    sub->add_option("--sun-elevation-deg", o->s.sun_elevation_deg, "Sun elevation above the observer's horizon")
        ->check(real_in(-90.0, 90.0, "degrees"))
        ->required();
    sub->add_option("--sun-azimuth-deg", o->s.sun_azimuth_deg, "Sun azimuth, degrees from +x towards +y")
        ->check(real_in(-360.0, 360.0, "degrees"))
        ->capture_default_str();
    sub->add_option("--view", o->view, "fisheye (upper hemisphere), panorama (360x180) or camera")
        ->capture_default_str();
    sub->add_option("--fov", o->s.fov_deg, "Camera only: horizontal field of view, degrees")
        ->check(real_in(0.0, 180.0, "degrees", End::Open, End::Open))
        ->capture_default_str();
    sub->add_option("--yaw", o->s.yaw_deg, "Camera only: azimuth of the view centre, degrees")
        ->check(real_in(-360.0, 360.0, "degrees"))
        ->capture_default_str();
    sub->add_option("--pitch", o->s.pitch_deg, "Camera only: elevation of the view centre, degrees")
        ->check(real_in(-90.0, 90.0, "degrees"))
        ->capture_default_str();
    sub->add_option("--size", o->size, "Image size WxH in pixels")->capture_default_str();
    sub->add_option("-o,--output", o->output, "Output image: .png (tone-mapped sRGB) or .exr (linear)")->required();
    sub->add_option("--method", o->method, "tables or exact (slow)")->capture_default_str();
    sub->add_option("--steps", o->steps, "Steps of the sum per view ray")
        ->check(integer_in(1, 4096))
        ->capture_default_str();
    sub->add_option("--device", o->device, "cpu or cuda (tables method and networks)")->capture_default_str();
    sub->add_option("--exposure", o->exposure, "PNG only: exposure in stops, or auto (the 98th percentile of "
                                               "luminance maps to white)")
        ->check(auto_or_real_in(-64.0, 64.0, "stops"))
        ->capture_default_str();
    sub->add_option("--tone", o->tone, "PNG only: tone curve, aces, reinhard or clamp")->capture_default_str();
    sub->add_flag("--no-sun", o->no_sun, "Do not draw the sun disc");
    sub->add_option("--ground", o->ground, "Ground model: lambert (physical) or as-published (Pietras & Rudnicki's b-scaled term; also: seed)")
        ->capture_default_str();
    sub->add_option("--renderer", o->renderer,
                    "cpu (the per-pixel renderer) or gl (the OpenGL planet renderer; camera views)")
        ->capture_default_str();
    o->gl.add(*sub, false);
    add_json_flag(*sub, o->json);
    sub->callback([o, sub] {
        check_output_path(o->output, {".png", ".exr"}, "--output");
        const bool neural = o->model.active();
        const NeuralSky net = neural ? o->model.load(*sub, o->atm) : NeuralSky{};
        const Atmosphere atm = neural ? net.atmosphere : o->atm.load(*sub);
        const Device device = parse_flag("--device", [&] { return parse_device(o->device); });
        if (o->view == "fisheye")
            o->s.view = SkyView::Fisheye;
        else if (o->view == "panorama")
            o->s.view = SkyView::Panorama;
        else if (o->view == "camera")
            o->s.view = SkyView::Camera;
        else
            throw UsageError("unknown view '" + o->view + "'; use fisheye, panorama or camera", "--view");
        if (o->s.view != SkyView::Camera)
            for (const char* f : {"--fov", "--yaw", "--pitch"})
                refuse_if_given(*sub, f, "to --view " + o->view + " (camera only)");
        parse_flag("--size", [&] { parse_size(o->size, o->s.width, o->s.height, "--size"); });
        o->s.method = neural ? SkyMethod::Tables : parse_sky_method(o->method);
        if (o->s.method == SkyMethod::Exact) {
            refuse_if_given(*sub, "--steps", "to --method exact");
            if (device == Device::Cuda)
                throw UsageError("the exact method runs on the CPU only; use --device cpu or --method tables",
                                 "--device cuda");
        }
        o->s.sun_disc = !o->no_sun;
        if (o->ground != "lambert" && o->ground != "as-published" && o->ground != "seed")
            throw UsageError("unknown ground model '" + o->ground + "'; use lambert or as-published", "--ground");
        o->s.published_ground = o->ground != "lambert";
        ToneMap tm;
        tm.curve = parse_flag("--tone", [&] { return parse_tone_curve(o->tone); });
        if (lower_extension(o->output) == ".exr")
            for (const char* f : {"--exposure", "--tone"})
                refuse_if_given(*sub, f, "to an .exr output (linear radiance)");
        const bool gl = o->renderer == "gl";
        if (!gl && o->renderer != "cpu")
            throw UsageError("unknown renderer '" + o->renderer + "'; use cpu or gl", "--renderer");
        if (gl && o->s.view != SkyView::Camera)
            throw UsageError("the OpenGL renderer draws camera views only; use --view camera", "--renderer gl");
        if (gl && (o->s.method == SkyMethod::Exact || device == Device::Cuda))
            throw UsageError("the OpenGL renderer uses the tables; drop --method exact and --device cuda",
                             "--renderer gl");
        if (!gl)
            o->gl.refuse(*sub, "to --renderer cpu (OpenGL only)");
        const PlanetRenderOptions gl_options = o->gl.options(neural ? PlanetSky::Network : PlanetSky::Reference);
        SkyModelOptions opts;
        opts.steps = o->steps;
        const auto t0 = std::chrono::steady_clock::now();
        // What computes the sky, and where: one object (no GPU: exit 1 here).
        const SkySource source = neural ? SkySource::network(net, device)
                                        : SkySource::reference(SkyModel(atm, opts), o->s.method, device);
        const Image img = gl ? render_sky_gl(source.tables(), neural ? &source.network_weights() : nullptr, o->s,
                                             gl_options)
                             : source.render(o->s);
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        tm.exposure_ev = o->exposure == "auto" ? float(auto_exposure_ev(img)) : std::stof(o->exposure);
        save_image(o->output, img, tm);
        info("{}x{} {} view from {} km, sun at {} deg: {:.2f} s -> {} (exposure {:+.2f} EV)", o->s.width, o->s.height,
             o->view, o->s.altitude_km, o->s.sun_elevation_deg, seconds, o->output, tm.exposure_ev);
        if (o->json)
            print_json({{"atmosphere", atm.name},
                        {"view", o->view},
                        {"width", o->s.width},
                        {"height", o->s.height},
                        {"altitude_km", o->s.altitude_km},
                        {"sun_elevation_deg", o->s.sun_elevation_deg},
                        {"method", neural ? std::string("neural") : o->method},
                        {"model", o->model.path},
                        {"ground", o->ground},
                        {"device", o->device},
                        {"renderer", o->renderer},
                        {"exposure_ev", tm.exposure_ev},
                        {"seconds", seconds},
                        {"output", o->output}});
    });
}

SKYBAKE_CLI_COMMAND("sky", add_sky_render)

} // namespace skybake::cli
