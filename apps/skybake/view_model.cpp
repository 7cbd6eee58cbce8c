// skybake view MODEL.glb --screenshot OUT.png|.exr [--size WxH] [--sun-elevation-deg E]
//                        [--sun-azimuth-deg A] [--altitude-km H] [--model W.json | --preset P]
//                        [--rule R] [--frames N] [--set key=value ...]
// A model lit by the sky on OpenGL (skybake/viewer.h), rendered headless.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "cli.h"
#include "commands.h"
#include "flags.h"
#include "sky_common.h"
#include "skybake/viewer.h"

namespace skybake::cli {

namespace {

struct ViewModelOpts {
    AtmosphereFlags atm;
    ModelFlag model;
    std::string input, screenshot, size = "960x720", rule = "lebedev:2030";
    std::vector<std::string> set;
    double elevation = 30.0, azimuth = 0.0, altitude = 0.0;
    int frames = 1;
};

double parse_number(const std::string& key, const std::string& value, double lo, double hi) {
    std::size_t used = 0;
    double x = 0.0;
    try {
        x = std::stod(value, &used);
    } catch (const std::exception&) {
    }
    if (used != value.size() || !(x >= lo && x <= hi))
        throw UsageError(fmt::format("{}={} is not a number in [{}, {}]", key, value, lo, hi), "--set");
    return x;
}

void run(const ViewModelOpts& o, const CLI::App& sub) {
    if (o.screenshot.empty())
        throw UsageError("the window viewer is not available in this build; render an image with --screenshot "
                         "OUT.png",
                         "--screenshot");
    check_output_path(o.screenshot, {".png", ".exr"}, "--screenshot");
    ModelViewSettings st;
    parse_flag("--size", [&] { parse_size(o.size, st.camera.width, st.camera.height, "--size"); });
    st.sun_elevation_deg = o.elevation;
    st.sun_azimuth_deg = o.azimuth;
    st.altitude_km = o.altitude;
    bool auto_exposure = true;
    float exposure_ev = 0.0f;
    std::vector<float> albedo;
    for (const std::string& kv : o.set) {
        const auto eq = kv.find('=');
        if (eq == std::string::npos || eq == 0)
            throw UsageError(fmt::format("'{}' is not key=value", kv), "--set");
        const std::string key = kv.substr(0, eq), value = kv.substr(eq + 1);
        if (key == "exposure") {
            auto_exposure = value == "auto";
            if (!auto_exposure)
                exposure_ev = float(parse_number(key, value, -64.0, 64.0));
        } else if (key == "shading") {
            st.shading = parse_flag("--set", [&] { return parse_model_shading(value); });
        } else if (key == "view") {
            const auto comma = value.find(',');
            if (comma == std::string::npos)
                throw UsageError(fmt::format("view={} is not AZIMUTH,ELEVATION in degrees", value), "--set");
            st.camera.azimuth_deg = float(parse_number(key, value.substr(0, comma), -360.0, 360.0));
            st.camera.elevation_deg = float(parse_number(key, value.substr(comma + 1), -90.0, 90.0));
        } else if (key == "fov") {
            st.camera.fov_y_deg = float(parse_number(key, value, 2.0, 160.0));
        } else if (key == "samples") {
            st.camera.samples = int(parse_number(key, value, 1.0, 8.0));
        } else if (key == "sun") {
            if (value != "on" && value != "off")
                throw UsageError(fmt::format("sun={} is not on or off", value), "--set");
            st.sun = value == "on";
        } else if (key == "background") {
            if (value != "sky" && value != "none")
                throw UsageError(fmt::format("background={} is not sky or none", value), "--set");
            st.sky_background = value == "sky";
        } else if (key == "albedo") {
            std::istringstream s(value);
            std::string part;
            while (std::getline(s, part, ','))
                albedo.push_back(float(parse_number(key, part, 0.0, 1.0)));
            if (albedo.size() != 1 && albedo.size() != 3)
                throw UsageError(fmt::format("albedo={} is not one value or R,G,B in [0, 1]", value), "--set");
        } else {
            throw UsageError(fmt::format("unknown setting '{}'; use exposure, shading, view, fov, samples, sun, "
                                         "background or albedo",
                                         key),
                             "--set");
        }
    }
    const SphereRule rule = parse_flag("--rule", [&] { return parse_rule(o.rule); });
    const bool neural = o.model.active();
    const SkySource sky =
        neural ? SkySource::network(o.model.load(sub, o.atm)) : SkySource::reference(SkyModel(o.atm.load(sub)));

    ViewerModel model = load_viewer_model(o.input);
    if (!albedo.empty()) {
        const glm::vec3 a = albedo.size() == 1 ? glm::vec3(albedo[0]) : glm::vec3(albedo[0], albedo[1], albedo[2]);
        std::fill(model.albedo.begin(), model.albedo.end(), a);
    }
    const int order = model.has_transfer() ? model.transfer.order : 3;
    ModelRenderer renderer(model, sky, rule, order);
    ModelFrameStats stats;
    Image img = renderer.render(st, &stats);
    // Further frames of the same view: the mean draw time of a steady frame.
    double draw = 0.0;
    for (int i = 1; i < o.frames; ++i) {
        ModelFrameStats again;
        img = renderer.render(st, &again);
        draw += again.draw_seconds;
    }
    if (auto_exposure) {
        // The 95th percentile luminance (Rec. 709) of the frame maps to 0.6.
        std::vector<float> lum;
        for (int y = 0; y < img.height; ++y)
            for (int x = 0; x < img.width; ++x) {
                const float* p = img.pixel(x, y);
                if (const float l = 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2]; l > 0.0f && std::isfinite(l))
                    lum.push_back(l);
            }
        if (!lum.empty()) {
            const auto k = std::ptrdiff_t(0.95 * double(lum.size() - 1));
            std::nth_element(lum.begin(), lum.begin() + k, lum.end());
            exposure_ev = std::log2(0.6f / lum[std::size_t(k)]);
        }
    }
    if (lower_extension(o.screenshot) == ".exr") {
        Image scaled = img;
        const float k = std::exp2(exposure_ev);
        for (int y = 0; y < scaled.height; ++y)
            for (int x = 0; x < scaled.width; ++x)
                for (int c = 0; c < 3; ++c)
                    scaled.pixel(x, y)[c] *= k;
        save_image(o.screenshot, scaled);
    } else {
        save_image(o.screenshot, img, ToneMap{exposure_ev, ToneCurve::Aces});
    }
    if (!model.has_transfer() && st.shading != ModelShading::Unshadowed)
        info("{} has no baked transfer: shading unshadowed (bake one with `skybake prt bake`)", o.input);
    if (o.frames > 1)
        info("{} frames: {:.2f} ms per frame after the first ({})", o.frames, 1e3 * draw / double(o.frames - 1),
             renderer.device_description());
    info("drew {} vertices, {} triangles ({} shading, SH order {}{}) in {:.3f} s (sky SH {:.3f} s, sun {:.3f} s) "
         "at exposure {:+.2f} EV; wrote {}",
         stats.vertices, stats.triangles, model_shading_name(stats.shading), stats.sh_order,
         model.normals_computed ? ", normals computed" : "", stats.draw_seconds, stats.light_seconds, stats.sun_seconds,
         exposure_ev, o.screenshot);
}

} // namespace

// `skybake view MODEL.glb` is the group itself; `skybake view planet` its sub-command.
void add_view_model(CLI::App& group) {
    auto o = std::make_shared<ViewModelOpts>();
    group.require_subcommand(0, 1);
    group.add_option("input", o->input, "Mesh to view: written by 'prt bake' (with its .prt.json) or any mesh");
    group.add_option("--screenshot", o->screenshot,
                     "Render headless (EGL) to this .png (tone-mapped) or .exr (linear)");
    group.add_option("--size", o->size, "Image size WxH in pixels")->capture_default_str();
    o->atm.add(group);
    o->model.add(group);
    group.add_option("--sun-elevation-deg", o->elevation, "Sun above the horizon, degrees")
        ->check(real_in(-90.0, 90.0, "degrees"))
        ->capture_default_str();
    group.add_option("--sun-azimuth-deg", o->azimuth, "Sun azimuth, degrees: 0 towards +z, 90 towards +x")
        ->check(real_in(-360.0, 360.0, "degrees"))
        ->capture_default_str();
    group.add_option("--altitude-km", o->altitude, "Observer above the ground, km")
        ->check(real_in(0.0, 1e6, "km"))
        ->capture_default_str();
    group.add_option("--frames", o->frames, "Frames to draw (the last is written); prints the mean frame time")
        ->check(integer_in(1, 100000))
        ->capture_default_str();
    group.add_option("--rule", o->rule, "Sphere rule of the sky's SH projection")->capture_default_str();
    group.add_option("--set", o->set,
                     "key=value: exposure=EV|auto, shading=prt|ao|a|unshadowed, view=AZ,EL, fov=DEG, samples=N, "
                     "sun=on|off, background=sky|none, albedo=A|R,G,B");
    group.callback([o, &group] {
        if (group.get_subcommands().empty()) {
            if (o->input.empty())
                throw UsageError("give a mesh to view (skybake view MODEL.glb --screenshot OUT.png) or a sub-command "
                                 "(skybake view planet)",
                                 "input");
            run(*o, group);
        }
    });
}

SKYBAKE_CLI_COMMAND("view", add_view_model)

} // namespace skybake::cli
