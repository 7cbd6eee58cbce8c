// skybake view MODEL.glb [--screenshot OUT.png|.exr] [--size WxH] [--sun-elevation-deg E]
//                        [--sun-azimuth-deg A] [--altitude-km H] [--model W.json | --preset P]
//                        [--rule R] [--frames N] [--set key=value ...]
//                        [--screenshot-path P.png] [--window-capture OUT.png] [--bake] [--fold-panel]
// A model lit by the sky on OpenGL (skybake/viewer.h): without --screenshot
// in a window with a Dear ImGui panel, else rendered headless.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <sstream>

#include "cli.h"
#include "commands.h"
#include "flags.h"
#include "sky_common.h"
#include "skybake/bake_job.h"
#include "skybake/viewer.h"
#include "skybake/visibility.h"
#include "skybake/image_io.h"

namespace skybake::cli {

namespace {

namespace fs = std::filesystem;

struct ViewModelOpts {
    AtmosphereFlags atm;
    ModelFlag model;
    std::string input, screenshot, window_capture, screenshot_path = "skybake_view.png", size = "960x720", rule = kSkyLightRule;
    std::vector<std::string> set;
    double elevation = 30.0, azimuth = 0.0, altitude = 0.0;
    int frames = 1;
    bool frames_given = false, bake = false, fold_panel = false;
};

// The panel's Bake button: `skybake prt bake`'s defaults (order 3, shadowed,
// lebedev:590) on the device "auto" picks (a CUDA GPU when one answers, else
// the CPU), as every front end resolves it (resolve_tracer()).
std::function<ViewerModel(const ViewerModel&)> make_viewer_bake() {
    return [](const ViewerModel& in) {
        ViewerModel out = in;
        BakeJob job; // device auto
        job.rule = parse_rule("lebedev:590");
        job.shading = false;
        job.transfer.emplace();
        job.transfer->order = 3;
        job.albedo = out.albedo;
        out.transfer = run_bake_job(out.mesh, job).transfer;
        return out;
    };
}

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
    const bool window = o.screenshot.empty();
    if (window && !viewer_window_available())
        throw Error("this build has no window (GLFW or Dear ImGui was not found when it was configured); render an "
                    "image with --screenshot OUT.png",
                    "display");
    if (!window) {
        check_output_path(o.screenshot, {".png", ".exr"}, "--screenshot");
        if (o.bake)
            throw UsageError("--bake is for the window; headless, bake with `skybake prt bake`", "--bake");
        if (!o.window_capture.empty())
            throw UsageError("--window-capture is for the window; headless, --screenshot writes the image",
                             "--window-capture");
    }
    ModelViewSettings st;
    bool sky_network = o.model.active();
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
        } else if (key == "sky") {
            if (value != "network" && value != "reference")
                throw UsageError(fmt::format("sky={} is not network or reference", value), "--set");
            if (value == "network" && !o.model.active())
                throw UsageError("sky=network needs a network (--model W.json)", "--set");
            sky_network = value == "network";
        } else if (key == "phong") {
            st.phong_exponent = parse_number(key, value, 0.5, 100000.0);
        } else if (key == "specular") {
            st.specular = float(parse_number(key, value, 0.0, 100.0));
        } else if (key == "shadow") {
            st.sun_shadow = parse_flag("--set", [&] { return parse_sun_shadow(value); });
        } else if (key == "direction") {
            st.visibility_direction = int(parse_number(key, value, 0.0, 1e7));
        } else if (key == "zoom") {
            st.zoom = float(parse_number(key, value, 0.01, 100.0));
        } else if (key == "albedo") {
            std::istringstream s(value);
            std::string part;
            while (std::getline(s, part, ','))
                albedo.push_back(float(parse_number(key, part, 0.0, 1.0)));
            if (albedo.size() != 1 && albedo.size() != 3)
                throw UsageError(fmt::format("albedo={} is not one value or R,G,B in [0, 1]", value), "--set");
        } else {
            throw UsageError(fmt::format("unknown setting '{}'; use exposure, shading, view, fov, samples, sun, "
                                         "background, sky, phong, specular, shadow, direction, zoom or albedo",
                                         key),
                             "--set");
        }
    }
    // Settings that only one shading reads are refused with another, as the CLI
    // refuses flags that do not apply (the window can switch shading, but its
    // starting values then come from the panel).
    for (const std::string& kv : o.set) {
        const std::string key = kv.substr(0, kv.find('='));
        const bool dprt_only = key == "phong" || key == "specular", visibility_only = key == "direction";
        if ((dprt_only && st.shading != ModelShading::Dprt) ||
            (visibility_only && st.shading != ModelShading::Visibility))
            throw UsageError(fmt::format("{} applies to shading={} only; this view has shading={}", key,
                                         dprt_only ? "dprt" : "visibility", model_shading_name(st.shading)),
                             "--set");
    }
    const SphereRule rule = parse_flag("--rule", [&] { return parse_rule(o.rule); });
    if (rule.kind == RuleKind::Phong)
        throw UsageError(fmt::format("--rule {} is a Phong rule; use a sphere rule (lebedev:2030, ...)", rule.spec),
                         "--rule");
    // The network (--model) and the reference sky: that of --preset/--atmosphere, or the network's own tables.
    // The reference sky's tables take seconds (the optical lengths): they are
    // built only where they are drawn, the window (its panel offers both skies)
    // or sky=reference, not for a headless frame of the network.
    std::optional<SkySource> network, reference;
    if (o.model.active()) {
        NeuralSky net = o.model.load(sub, o.atm);
        if (window || !sky_network)
            reference.emplace(SkySource::reference(neural_reference_model(net)));
        network.emplace(SkySource::network(std::move(net)));
    } else {
        reference.emplace(SkySource::reference(SkyModel(o.atm.load(sub))));
    }

    ViewerModel model = load_viewer_model(o.input);
    if (!albedo.empty()) {
        const glm::vec3 a = albedo.size() == 1 ? glm::vec3(albedo[0]) : glm::vec3(albedo[0], albedo[1], albedo[2]);
        std::fill(model.albedo.begin(), model.albedo.end(), a);
    }
    if (window) {
        ModelViewerOptions vo;
        vo.view = st;
        vo.auto_exposure = auto_exposure;
        vo.exposure_ev = exposure_ev;
        vo.frames = o.frames_given ? o.frames : 0;
        vo.network = network ? &*network : nullptr;
        vo.reference = &*reference;
        vo.start_network = sky_network;
        vo.light_rule = rule;
        vo.title = fmt::format("skybake view {}", fs::path(o.input).filename().string());
        vo.bake = make_viewer_bake();
        vo.screenshot = o.screenshot_path;
        vo.last_frame = o.window_capture;
        vo.bake_at_start = o.bake;
        vo.panel_folded = o.fold_panel;
        if (!o.window_capture.empty() && !o.frames_given)
            throw UsageError("--window-capture needs --frames N (the frame it writes is the last)", "--window-capture");
        if (!o.window_capture.empty())
            check_output_path(o.window_capture, {".png"}, "--window-capture");
        run_model_viewer(model, vo); // the panel says when the model has no transfer (and offers to bake one)
        return;
    }
    const SkySource& sky = sky_network ? *network : *reference;
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
    if (auto_exposure) // the 95th percentile luminance (Rec. 709) of the frame maps to 0.6
        exposure_ev = model_auto_exposure_ev(img);
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
    group.add_option("--screenshot-path", o->screenshot_path, "In the window: where the P key writes a PNG")
        ->capture_default_str();
    group.add_option("--window-capture", o->window_capture,
                     "In the window with --frames N: write the last frame as shown, panel included (PNG)");
    group.add_flag("--bake", o->bake,
                   "In the window: bake the transfer at once when the model has none (as the panel's button)");
    group.add_flag("--fold-panel", o->fold_panel, "In the window: start with the panel folded");
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
    group.add_option("--frames", o->frames,
                     "Frames to draw (the last is written); prints the mean frame time. In the window: close "
                     "after N frames")
        ->check(integer_in(1, 100000))
        ->capture_default_str();
    group.add_option("--rule", o->rule, "Sphere rule of the sky's SH projection")->capture_default_str();
    group.add_option("--set", o->set,
                     "key=value: exposure=EV|auto, shading=prt|ao|a|unshadowed|dprt|visibility, view=AZ,EL, fov=DEG, "
                     "samples=N, sun=on|off, background=sky|none, sky=network|reference, phong=A, specular=K, "
                     "shadow=map|vertex|none, direction=K, zoom=F, albedo=A|R,G,B");
    group.callback([o, &group] {
        if (group.get_subcommands().empty()) {
            if (o->input.empty())
                throw UsageError("give a mesh to view (skybake view MODEL.glb --screenshot OUT.png) or a sub-command "
                                 "(skybake view planet)",
                                 "input");
            o->frames_given = group.count("--frames") > 0;
            run(*o, group);
        }
    });
}

SKYBAKE_CLI_COMMAND("view", add_view_model)

} // namespace skybake::cli
