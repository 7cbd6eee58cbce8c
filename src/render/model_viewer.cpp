// `skybake view MODEL.glb` in a window: ModelRenderer in the window shell's
// context (window_shell.h), with a Dear ImGui panel for the sun, the
// observer, the sky, the shading and the exposure, an orbit camera and an
// overlay of frame statistics. A model without a transfer can be baked from
// the panel on a worker thread (ModelViewerOptions::bake), with a progress
// bar and a Cancel button; the window keeps drawing meanwhile.
//
// Keys: left drag orbits, the wheel zooms, R resets the camera, P writes a
// screenshot (PNG), Space toggles the sun's animation, arrows move the sun,
// +/- the exposure, Esc quits.
#if defined(SKYBAKE_HAS_WINDOW)

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <future>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <imgui.h>

#include "render/window_shell.h" // GL and GLFW first
#include "skybake/error.h"
#include "skybake/interrupt.h"
#include "skybake/neural.h"
#include "skybake/progress.h"
#include "skybake/sky.h"
#include "skybake/viewer.h"

namespace skybake {

using namespace render;

bool viewer_window_available() {
    return true;
}

namespace {

// The skies that the panel's atmosphere or weights choice builds off the window thread.
struct SkySwitch {
    std::unique_ptr<SkySource> network; // none for a preset
    std::unique_ptr<SkySource> reference;
};

// A bake on a worker thread, reporting through the progress callback, which
// throws skybake::Interrupted once Cancel was pressed.
class BakeJob {
public:
    BakeJob(const std::function<ViewerModel(const ViewerModel&)>& bake, const ViewerModel& model) {
        previous_ = set_progress_callback([this](const ProgressEvent& e) {
            if (e.total > 0)
                fraction_ = float(double(e.done) / double(e.total));
            if (cancel_)
                throw Interrupted(SIGINT);
        });
        result_ = std::async(std::launch::async, [bake, model] { return bake(model); });
    }
    ~BakeJob() {
        cancel_ = true;
        if (result_.valid())
            result_.wait();
        set_progress_callback(previous_);
    }
    float fraction() const { return fraction_; }
    void cancel() { cancel_ = true; }
    bool cancelled() const { return cancel_; }
    bool ready() const { return result_.wait_for(std::chrono::seconds(0)) == std::future_status::ready; }
    // The baked model (ready() only); rethrows the bake's error.
    ViewerModel take() { return result_.get(); }

private:
    ProgressCallback previous_;
    std::atomic<float> fraction_{0.0f};
    std::atomic<bool> cancel_{false};
    std::future<ViewerModel> result_;
};

} // namespace

void run_model_viewer(const ViewerModel& start_model, const ModelViewerOptions& o) {
    if (!o.reference)
        throw Error("the viewer needs the reference sky (and may have a network)", "sky");
    WindowShell shell(o.view.camera.width, o.view.camera.height, o.title, o.frames);
    ToneMapper tone;
    ViewerModel model = start_model;
    // The skies: those of the command line, or ones chosen in the panel (a preset, a weights file).
    const SkySource* network = o.network;
    const SkySource* reference = o.reference;
    std::unique_ptr<SkySource> own_network, own_reference;
    bool use_network = o.start_network && network;
    std::unique_ptr<ModelRenderer> renderer;
    auto rebuild = [&] {
        renderer.reset();
        const SkySource& sky = use_network ? *network : *reference;
        const int order = model.has_transfer() ? model.transfer.order : 3;
        renderer = std::make_unique<ModelRenderer>(model, sky, o.light_rule, order, ModelRenderer::InCurrentContext{});
    };
    rebuild();

    ModelViewSettings st = o.view;
    OrbitCamera orbit;
    orbit.start(st.camera.azimuth_deg, st.camera.elevation_deg, st.zoom);
    float exposure = o.exposure_ev;
    bool need_auto_exposure = o.auto_exposure, animate = false;
    float sun_el = float(st.sun_elevation_deg), sun_az = float(st.sun_azimuth_deg), altitude = float(st.altitude_km);
    float phong = float(st.phong_exponent), specular = st.specular;
    glm::vec3 albedo = model.albedo.empty() ? glm::vec3(0.8f) : model.albedo.front();
    bool albedo_override = false;
    int shading = int(st.shading), shadow = int(st.sun_shadow), direction = st.visibility_direction;
    const std::vector<std::string> presets = atmosphere_preset_names();
    std::string preset_label = "(command line)";
    char weights_path[512] = "";
    std::future<SkySwitch> pending_sky; // the skies being built for the panel's choice
    std::string pending_label;
    std::unique_ptr<BakeJob> bake;
    std::string bake_message;
    std::string message;
    ModelFrameStats stats;

    const auto bake_started = std::chrono::steady_clock::now();
    if (o.bake_at_start && o.bake && !model.has_transfer())
        bake = std::make_unique<BakeJob>(o.bake, model);
    while (shell.begin_frame()) {
        const double dt = shell.seconds_per_frame();
        orbit.update(shell);
        if (shell.key_pressed(GLFW_KEY_SPACE))
            animate = !animate;
        if (shell.key_down(GLFW_KEY_LEFT))
            sun_az -= float(30.0 * dt);
        if (shell.key_down(GLFW_KEY_RIGHT))
            sun_az += float(30.0 * dt);
        if (shell.key_down(GLFW_KEY_UP))
            sun_el = std::min(90.0f, sun_el + float(10.0 * dt));
        if (shell.key_down(GLFW_KEY_DOWN))
            sun_el = std::max(-90.0f, sun_el - float(10.0 * dt));
        if (shell.key_down(GLFW_KEY_EQUAL) || shell.key_down(GLFW_KEY_KP_ADD))
            exposure += float(2.0 * dt);
        if (shell.key_down(GLFW_KEY_MINUS) || shell.key_down(GLFW_KEY_KP_SUBTRACT))
            exposure -= float(2.0 * dt);
        // The animation sweeps the sun around the sky, 20 degrees of azimuth a second.
        if (animate)
            sun_az = float(std::remainder(double(sun_az) + 20.0 * dt, 360.0));
        const bool screenshot = shell.key_pressed(GLFW_KEY_P);

        // The panel.
        ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_FirstUseEver);
        ImGui::SetNextWindowCollapsed(o.panel_folded, ImGuiCond_FirstUseEver);
        ImGui::Begin("skybake view", nullptr, ImGuiWindowFlags_AlwaysAutoResize);
        ImGui::SliderFloat("sun elevation", &sun_el, -20.0f, 90.0f, "%.1f deg");
        ImGui::SliderFloat("sun azimuth", &sun_az, -180.0f, 180.0f, "%.1f deg");
        ImGui::Checkbox("animate the sun (Space)", &animate);
        ImGui::SliderFloat("altitude", &altitude, 0.0f, 20.0f, "%.2f km");
        int sky_choice = use_network ? 0 : 1;
        if (network && reference) {
            if (ImGui::Combo("sky", &sky_choice, "network\0reference\0") && (sky_choice == 0) != use_network) {
                use_network = sky_choice == 0;
                rebuild();
            }
        } else {
            ImGui::Text("sky: %s", use_network ? "network" : "reference");
        }
        // Another atmosphere: a preset or a weights file. Its tables are built
        // on a worker thread while the window keeps drawing the current sky;
        // the new one replaces it at the first frame after they are ready.
        const bool switching = pending_sky.valid();
        if (switching) {
            ImGui::Text("building the tables of %s ...", pending_label.c_str());
        } else if (ImGui::BeginCombo("atmosphere", preset_label.c_str())) {
            for (const std::string& name : presets)
                if (ImGui::Selectable(name.c_str(), name == preset_label)) {
                    pending_label = name;
                    pending_sky = std::async(std::launch::async, [name] {
                        SkySwitch next;
                        next.reference =
                            std::make_unique<SkySource>(SkySource::reference(SkyModel(atmosphere_preset(name))));
                        return next;
                    });
                }
            ImGui::EndCombo();
        }
        ImGui::InputText("weights", weights_path, sizeof weights_path);
        ImGui::SameLine();
        if (ImGui::Button("load") && !switching) {
            pending_label = std::filesystem::path(weights_path).filename().string();
            pending_sky = std::async(std::launch::async, [path = std::string(weights_path)] {
                SkySwitch next;
                NeuralSky net = load_neural_sky(path);
                next.reference = std::make_unique<SkySource>(SkySource::reference(neural_reference_model(net)));
                next.network = std::make_unique<SkySource>(SkySource::network(std::move(net)));
                return next;
            });
        }
        if (pending_sky.valid() &&
            pending_sky.wait_for(std::chrono::seconds(0)) == std::future_status::ready) {
            try {
                SkySwitch next = pending_sky.get();
                renderer.reset(); // it points at the skies it replaces
                // A weights file brings its network and shows it; a preset
                // has only the reference sky, and shows that.
                use_network = next.network != nullptr;
                if (next.network) {
                    own_network = std::move(next.network);
                    network = own_network.get();
                }
                own_reference = std::move(next.reference);
                reference = own_reference.get();
                preset_label = pending_label;
                rebuild();
                message.clear();
            } catch (const Error& e) {
                message = e.what();
            }
        }
        ImGui::Checkbox("sky background", &st.sky_background);
        ImGui::Checkbox("sun", &st.sun);
        ImGui::Combo("shading", &shading, "prt\0ao\0a\0unshadowed\0dprt\0visibility\0");
        ImGui::Combo("sun shadow", &shadow, "shadow map\0per vertex\0none\0");
        if (shading == int(ModelShading::Dprt)) {
            ImGui::SliderFloat("Phong exponent", &phong, 1.0f, 512.0f, "%.0f", ImGuiSliderFlags_Logarithmic);
            ImGui::SliderFloat("specular", &specular, 0.0f, 2.0f);
        }
        if (shading == int(ModelShading::Visibility))
            ImGui::SliderInt("rule direction", &direction, 0, int(o.light_rule.size()) - 1);
        if (ImGui::ColorEdit3("albedo", &albedo.x))
            albedo_override = true;
        ImGui::SliderFloat("exposure", &exposure, -16.0f, 16.0f, "%+.2f EV");
        ImGui::SameLine();
        if (ImGui::Button("auto"))
            need_auto_exposure = true;
        if (ImGui::Button("reset camera (R)"))
            orbit.reset();
        if (!model.has_transfer()) {
            ImGui::Separator();
            if (!o.bake) {
                ImGui::TextUnformatted("no baked transfer: unshadowed");
            } else if (!bake) {
                ImGui::TextUnformatted("no baked transfer: unshadowed");
                if (ImGui::Button("bake the transfer"))
                    bake = std::make_unique<BakeJob>(o.bake, model);
                ImGui::SameLine();
                ImGui::TextDisabled("(order 3, lebedev:590)");
            } else {
                ImGui::ProgressBar(bake->fraction(), ImVec2(200, 0));
                ImGui::SameLine();
                if (ImGui::Button("cancel"))
                    bake->cancel();
            }
            if (!bake_message.empty())
                ImGui::TextUnformatted(bake_message.c_str());
        }
        if (!message.empty())
            ImGui::TextUnformatted(message.c_str());
        ImGui::End();

        if (bake && bake->ready()) {
            try {
                ViewerModel baked = bake->take();
                if (!bake->cancelled()) {
                    renderer.reset();
                    model = std::move(baked);
                    rebuild();
                    bake_message.clear();
                    fmt::print(stderr, "baked the transfer of {} vertices (order {}) in {:.2f} s\n",
                               model.mesh.vertex_count(), model.transfer.order,
                               std::chrono::duration<double>(std::chrono::steady_clock::now() - bake_started).count());
                }
            } catch (const Error& e) {
                bake_message = bake->cancelled() ? "bake cancelled" : fmt::format("bake failed: {}", e.what());
                fmt::print(stderr, "{}\n", bake_message);
            }
            bake.reset();
        }
        if (albedo_override) {
            std::fill(model.albedo.begin(), model.albedo.end(), albedo);
            renderer->set_albedo(model.albedo);
            albedo_override = false;
        }

        const int w = shell.framebuffer_width(), h = shell.framebuffer_height();
        if (w < 1 || h < 1) {
            shell.end_frame();
            continue;
        }
        st.camera.width = w;
        st.camera.height = h;
        st.camera.azimuth_deg = orbit.azimuth_deg;
        st.camera.elevation_deg = orbit.elevation_deg;
        st.zoom = orbit.zoom;
        st.sun_elevation_deg = sun_el;
        st.sun_azimuth_deg = sun_az;
        st.altitude_km = altitude;
        st.shading = ModelShading(shading);
        st.sun_shadow = SunShadow(shadow);
        st.phong_exponent = phong;
        st.specular = specular;
        st.visibility_direction = direction;
        const unsigned texture = renderer->draw(st, &stats);
        if (need_auto_exposure) {
            exposure = model_auto_exposure_ev(renderer->read_last_draw());
            need_auto_exposure = false;
        }
        if (screenshot) {
            try {
                save_screenshot(o.screenshot, renderer->read_last_draw(), exposure);
                message = "wrote " + o.screenshot;
            } catch (const Error& e) {
                message = e.what();
            }
        }
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        tone.draw(texture, w, h, exposure);
        shell.overlay({fmt::format("{:.1f} fps", shell.fps()),
                       fmt::format("{} vertices, {} triangles", stats.vertices, stats.triangles),
                       fmt::format("SH order {}, {} shading", stats.sh_order, model_shading_name(stats.shading)),
                       fmt::format("draw {:.1f} ms", 1e3 * stats.draw_seconds)});
        const bool last = o.frames > 0 && shell.frames_drawn() + 1 == o.frames;
        shell.end_frame(last && !o.last_frame.empty() ? std::filesystem::path(o.last_frame) : std::filesystem::path());
    }
    if (bake) {
        bake->cancel();
        bake.reset();
        fmt::print(stderr, "bake cancelled (the window closed)\n");
    }
    renderer.reset();
}

} // namespace skybake

#endif // SKYBAKE_HAS_WINDOW
