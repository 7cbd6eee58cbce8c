// skybake fly: PNG frames of a flight along keyframes with the OpenGL planet
// renderer (headless), optionally joined into an MP4 by ffmpeg.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>

#include <nlohmann/json.hpp>
#include <unistd.h>

#include "commands.h"
#include "core/progress.h"
#include "flags.h"
#include "gl_flags.h"
#include "sky/render_hd.h"
#include "sky_common.h"
#include "skybake/files.h"
#include "skybake/interrupt.h"
#include "skybake/image_io.h"

namespace skybake::cli {

namespace {

namespace fs = std::filesystem;
constexpr double kDeg = 3.14159265358979323846 / 180.0;

struct Keyframe {
    double t = 0.0; // in [0, 1]
    double altitude_km = 0.002;
    double yaw_deg = 0.0, pitch_deg = 0.0, fov_deg = 90.0;
    double sun_elevation_deg = 20.0, sun_azimuth_deg = 30.0;
};

// From 2 m above the sea to 10,000 km, turning from the horizon to the planet below.
std::vector<Keyframe> sea_to_space() {
    return {{0.00, 0.002, 0.0, 8.0, 90.0, 12.0, 20.0},    {0.20, 0.5, 0.0, 4.0, 90.0, 12.0, 20.0},
            {0.40, 12.0, 0.0, -4.0, 90.0, 12.0, 20.0},    {0.60, 150.0, 0.0, -20.0, 80.0, 12.0, 20.0},
            {0.80, 1500.0, 0.0, -60.0, 70.0, 12.0, 20.0}, {1.00, 10000.0, 0.0, -90.0, 60.0, 12.0, 20.0}};
}

std::vector<Keyframe> load_path(const std::string& path) {
    const std::string text = read_file(path, 1 << 24);
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(text);
    } catch (const nlohmann::json::exception& e) {
        throw Error(std::string("not JSON: ") + e.what(), path);
    }
    if (!j.is_object() || !j.contains("keyframes") || !j["keyframes"].is_array() || j["keyframes"].size() < 2)
        throw Error("expected {\"keyframes\": [ ... ]} with at least two keyframes", path);
    std::vector<Keyframe> k;
    for (std::size_t i = 0; i < j["keyframes"].size(); ++i) {
        const auto& e = j["keyframes"][i];
        const std::string where = fmt::format("keyframe {} of {}", i, path);
        if (!e.is_object())
            throw Error("a keyframe must be an object", where);
        Keyframe f;
        auto num = [&](const char* name, double& out, double lo, double hi, bool required) {
            if (!e.contains(name)) {
                if (required)
                    throw Error(fmt::format("'{}' is missing", name), where);
                return;
            }
            if (!e[name].is_number() || !std::isfinite(e[name].get<double>()) || e[name].get<double>() < lo ||
                e[name].get<double>() > hi)
                throw Error(fmt::format("'{}' must be a number from {} to {}", name, readable(lo), readable(hi)),
                            where);
            out = e[name].get<double>();
        };
        num("t", f.t, 0.0, 1.0, true);
        num("altitude_km", f.altitude_km, 1e-4, 1e6, true);
        num("yaw_deg", f.yaw_deg, -360.0, 360.0, false);
        num("pitch_deg", f.pitch_deg, -90.0, 90.0, false);
        num("fov_deg", f.fov_deg, 1.0, 170.0, false);
        num("sun_elevation_deg", f.sun_elevation_deg, -90.0, 90.0, false);
        num("sun_azimuth_deg", f.sun_azimuth_deg, -360.0, 360.0, false);
        if (!k.empty() && !(f.t > k.back().t))
            throw Error("'t' must increase from one keyframe to the next", where);
        k.push_back(f);
    }
    if (k.front().t != 0.0 || k.back().t != 1.0)
        throw Error("the first keyframe must have t = 0 and the last t = 1", path);
    return k;
}

// Piecewise linear in t; the altitude in its logarithm (a steady climb rate in decades).
Keyframe interpolate(const std::vector<Keyframe>& k, double t) {
    std::size_t i = 0;
    while (i + 2 < k.size() && t > k[i + 1].t)
        ++i;
    const Keyframe &a = k[i], &b = k[i + 1];
    const double u = std::clamp((t - a.t) / (b.t - a.t), 0.0, 1.0);
    auto lerp = [&](double x, double y) { return x + (y - x) * u; };
    Keyframe f;
    f.t = t;
    f.altitude_km = std::exp(lerp(std::log(a.altitude_km), std::log(b.altitude_km)));
    f.yaw_deg = lerp(a.yaw_deg, b.yaw_deg);
    f.pitch_deg = lerp(a.pitch_deg, b.pitch_deg);
    f.fov_deg = lerp(a.fov_deg, b.fov_deg);
    f.sun_elevation_deg = lerp(a.sun_elevation_deg, b.sun_elevation_deg);
    f.sun_azimuth_deg = lerp(a.sun_azimuth_deg, b.sun_azimuth_deg);
    return f;
}

std::string find_ffmpeg() {
    const char* path = std::getenv("PATH");
    std::string p = path ? path : "";
    std::size_t start = 0;
    while (start <= p.size()) {
        const std::size_t end = p.find(':', start);
        const std::string dir = p.substr(start, end == std::string::npos ? std::string::npos : end - start);
        const fs::path f = fs::path(dir.empty() ? "." : dir) / "ffmpeg";
        std::error_code ec;
        if (fs::is_regular_file(f, ec))
            return f.string();
        if (end == std::string::npos)
            break;
        start = end + 1;
    }
    return {};
}

} // namespace

void add_fly(CLI::App& sub) {
    sub.description("Render PNG frames of a flight from sea level to space with the OpenGL planet renderer");
    struct Opts {
        ModelFlag model;
        std::string path = "sea-to-space", output, size = "640x480", exposure = "auto", sky = "network", mp4, strip;
        int frames = 60;
        int fps = 30;
        bool json = false;
        GlRenderFlags gl;
        std::string ground = "lambert";
    };
    auto o = std::make_shared<Opts>();
    sub.add_option("--model", o->model.path, "Trained neural sky (weights JSON from `skybake sky train`)")->required();
    o->model.add_aerosol(sub);
    sub.add_option("--path", o->path,
                   "sea-to-space (2 m to 10,000 km), or a JSON file {\"keyframes\": [{\"t\": 0, \"altitude_km\": "
                   "0.002, \"yaw_deg\", \"pitch_deg\", \"fov_deg\", \"sun_elevation_deg\", \"sun_azimuth_deg\"}, "
                   "..., {\"t\": 1, ...}]}")
        ->capture_default_str();
    sub.add_option("--frames", o->frames, "Number of frames")->check(integer_in(2, 100000))->capture_default_str();
    sub.add_option("-o,--output", o->output, "Folder for frame_0000.png, frame_0001.png, ... (created if missing)")->required();
    sub.add_option("--size", o->size, "Frame size WxH in pixels")->capture_default_str();
    sub.add_option("--sky", o->sky, "network, or reference (the seed's sum in GLSL, on the model's tables)")
        ->capture_default_str();
    sub.add_option("--exposure", o->exposure, "Exposure in stops, or auto (per frame, as `sky render`)")
        ->check(auto_or_real_in(-64.0, 64.0, "stops"))
        ->capture_default_str();
    sub.add_option("--mp4", o->mp4, "Also join the frames into this MP4 with ffmpeg (when installed)");
    sub.add_option("--strip", o->strip, "Also write every frame side by side into one PNG");
    sub.add_option("--fps", o->fps, "Frame rate of the MP4")->check(integer_in(1, 240))->capture_default_str();
    sub.add_option("--ground", o->ground, "Ground model: lambert (physical) or as-published (the paper's b-scaled term; also: seed)")
        ->capture_default_str();
    o->gl.add(sub, true);
    add_json_flag(sub, o->json);
    sub.callback([o, &sub] {
        std::error_code ec;
        int w = 0, h = 0;
        parse_flag("--size", [&] { parse_size(o->size, w, h, "--size"); });
        if (o->sky != "network" && o->sky != "reference")
            throw UsageError("unknown sky '" + o->sky + "'; use network or reference", "--sky");
        if (o->mp4.empty())
            refuse_if_given(sub, "--fps", "without --mp4");
        OutputFolder folder(o->output, "--output"); // created if missing, removed again on failure
        if (!o->strip.empty())
            check_output_path(o->strip, {".png"}, "--strip");
        std::string ffmpeg;
        if (!o->mp4.empty()) {
            check_output_path(o->mp4, {".mp4"}, "--mp4");
            ffmpeg = find_ffmpeg();
            if (ffmpeg.empty())
                throw Error("ffmpeg is not installed; install it (apt-get install ffmpeg) or drop --mp4", "--mp4");
        }
        PlanetRenderOptions options = o->gl.options(o->sky == "network" ? PlanetSky::Network : PlanetSky::Reference);
        if (o->ground != "lambert" && o->ground != "as-published" && o->ground != "seed")
            throw UsageError("unknown ground model '" + o->ground + "'; use lambert or as-published", "--ground");
        options.published_ground = o->ground != "lambert";
        const std::vector<Keyframe> keys = o->path == "sea-to-space" ? sea_to_space() : load_path(o->path);
        const NeuralSky net = o->model.load_weights();
        const SkyModel model = neural_reference_model(net);

        const auto t0 = std::chrono::steady_clock::now();
        PlanetRenderer renderer(model, &net, options);
        OutputSet files;
        std::vector<fs::path> staged_frames;
        std::vector<std::uint8_t> strip;
        const std::size_t strip_w = std::size_t(w) * std::size_t(o->frames);
        if (!o->strip.empty())
            strip.resize(strip_w * std::size_t(h) * 3);
        Progress progress("fly", std::uint64_t(o->frames));
        double max_tris = 0;
        for (int i = 0; i < o->frames; ++i) {
            const Keyframe k = interpolate(keys, double(i) / double(o->frames - 1));
            SkyRenderSettings s;
            s.view = SkyView::Camera;
            s.altitude_km = k.altitude_km;
            s.yaw_deg = k.yaw_deg;
            s.pitch_deg = k.pitch_deg;
            s.fov_deg = k.fov_deg;
            s.sun_elevation_deg = k.sun_elevation_deg;
            s.sun_azimuth_deg = k.sun_azimuth_deg;
            s.width = w;
            s.height = h;
            PlanetFrameStats st;
            const Image img = renderer.render(planet_view_from_settings(net.atmosphere, s), &st);
            max_tris = std::max(max_tris, double(st.triangles));
            ToneMap tm;
            tm.exposure_ev = o->exposure == "auto" ? float(auto_exposure_ev(img)) : std::stof(o->exposure);
            staged_frames.push_back(files.stage(fs::path(o->output) / fmt::format("frame_{:04d}.png", i)));
            save_png(staged_frames.back(), img, tm);
            if (!strip.empty()) {
                const std::vector<std::uint8_t> px = to_srgb8(img, tm);
                for (int y = 0; y < h; ++y)
                    std::copy_n(px.data() + std::size_t(y) * std::size_t(w) * 3, std::size_t(w) * 3,
                                strip.data() + (std::size_t(y) * strip_w + std::size_t(i) * std::size_t(w)) * 3);
            }
            check_interrupted();
            progress.advance();
        }
        progress.finish();
        if (!strip.empty())
            save_png_srgb8(files.stage(o->strip), int(strip_w), h, strip.data());
        if (!ffmpeg.empty()) {
            const fs::path staged = files.stage(o->mp4);
            // The staged frames carry staging names: link them under a pattern ffmpeg reads.
            const fs::path tmpdir = fs::path(o->output) / fmt::format(".skybake-fly-{}", ::getpid());
            fs::create_directories(tmpdir);
            for (std::size_t k = 0; k < staged_frames.size(); ++k)
                fs::copy_file(staged_frames[k], tmpdir / fmt::format("f{:05d}.png", k),
                              fs::copy_options::overwrite_existing);
            const std::string cmd = fmt::format(
                "'{}' -loglevel error -y -framerate {} -i '{}/f%05d.png' -c:v libx264 -pix_fmt yuv420p -f mp4 '{}'",
                ffmpeg, o->fps, tmpdir.string(), staged.string());
            const int rc = std::system(cmd.c_str());
            fs::remove_all(tmpdir, ec);
            if (rc != 0)
                throw Error(fmt::format("ffmpeg failed (exit status {})", rc), "--mp4");
        }
        files.commit();
        folder.keep();
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        info("{} frames {}x{} from {} km to {} km in {:.1f} s ({}) -> {} ...{}", o->frames, w, h,
             keys.front().altitude_km, keys.back().altitude_km, seconds, renderer.device_description(),
             (fs::path(o->output) / "frame_0000.png").string(),
             o->mp4.empty() ? "" : ", " + o->mp4);
        if (o->json)
            print_json({{"frames", o->frames},
                        {"width", w},
                        {"height", h},
                        {"path", o->path},
                        {"shading", o->gl.shading},
                        {"sky", o->sky},
                        {"max_triangles_used", max_tris},
                        {"seconds", seconds},
                        {"output", o->output},
                        {"mp4", o->mp4},
                        {"strip", o->strip}});
    });
}

SKYBAKE_CLI_GROUP_COMMAND("fly", add_fly)

} // namespace skybake::cli
