// skybake/viewer.h: a model lit by the sky in real time (OpenGL 3.3 core or
// newer), the renderer behind `skybake view MODEL.glb`. No GL types here.
//
// [SECTION] Model
// [SECTION] Settings
// [SECTION] Rendering (headless or in a window's context)
// [SECTION] Window
//
// Each frame: the background is the sky network evaluated per pixel (the GLSL
// of `skybake sky export`, weights in a uniform block), or for the reference
// sky an equirectangular map of it computed on the CPU when the sun or the
// altitude moves; the model's vertices are lit by the sky's SH (SkyProjector,
// recomputed when the sun or the altitude moves) through a per-vertex
// transfer with the GLSL of export_prt_glsl(), plus the sun as a direct light
// of the transmitted irradiance, shadowed by a shadow map (or per vertex by
// one occlusion ray, sun_visibility()). This is relight() of skybake/prt.h
// evaluated on the GPU, seen through the camera of the ray-cast previews
// (preview_camera()); the tests hold the two to PSNR ≥ 30 dB. See
// docs/viewer.md.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "skybake/bake.h"
#include "skybake/image.h"
#include "skybake/mesh.h"
#include "skybake/prt.h"
#include "skybake/sky_source.h"

namespace skybake {

// [SECTION] Model -------------------------------------------------------------------

// What lights the vertices:
//   prt         the baked transfer (shadowed or interreflected);
//   ao          unshadowed irradiance times the ambient occlusion 2√π T_00
//               of the baked transfer (channel 0);
//   a           unshadowed irradiance times the shading coefficient A of the
//               bake (seed 002's B ≈ A · B̃);
//   unshadowed  unshadowed irradiance: T_lm = (Â_l / π) Y_lm(n);
//   dprt        prt plus a glossy layer, DPRT (Svistunov, seed 002):
//               specular · A · Σ_k λ_k L(g_nv x_k) per pixel (dprt_glossy()
//               of the SH light, Phong exponent phong_exponent), as
//               render_prt_preview() draws it;
//   visibility  the visibility (1 or 0) of every vertex in one direction of
//               the light's sphere rule (visibility_direction), one ray per
//               vertex from the bake's ray origin, drawn as albedo × 1 or a
//               dark grey; the asset does not store the bake's visibility
//               words, so this is cast again, as the bake would.
enum class ModelShading : int { Prt = 0, Ao = 1, A = 2, Unshadowed = 3, Dprt = 4, Visibility = 5 };
// "prt", "ao", "a", "unshadowed", "dprt", "visibility".
const char* model_shading_name(ModelShading shading);
// Throws skybake::Error (where: "shading") listing the names.
ModelShading parse_model_shading(const std::string& text);

// A mesh to view, with its transfer when it has one.
struct ViewerModel {
    Mesh mesh;                     // normals computed when the file has none
    Transfer transfer;             // coeffs empty when the file has no transfer
    std::vector<glm::vec3> albedo; // vertex_count() entries, linear RGB
    bool normals_computed = false; // the file had none (load_mesh() or this computed them)
    bool has_transfer() const { return !transfer.coeffs.empty(); }
};
// A baked mesh (its .prt.json sidecar beside it: load_prt()) or any mesh that
// load_mesh() reads (no transfer; albedo from the vertex colours or 0.8).
// Throws skybake::Error as load_prt() and load_mesh().
ViewerModel load_viewer_model(const std::filesystem::path& path);

// [SECTION] Settings -----------------------------------------------------------------

// How the sun is shadowed: a shadow map (per pixel, 2048² texels over the
// bounding sphere, 3×3 percentage-closer filtering), one occlusion ray per
// vertex (sun_visibility(), interpolated across triangles; what `skybake prt
// relight` does), or not at all.
enum class SunShadow : int { Map = 0, Vertex = 1, None = 2 };
// "map", "vertex", "none".
const char* sun_shadow_name(SunShadow shadow);
// Throws skybake::Error (where: "shadow") listing the names.
SunShadow parse_sun_shadow(const std::string& text);

struct ModelViewSettings {
    AoPreviewOptions camera;         // size, azimuth, elevation, field of view, samples per pixel axis
    double sun_elevation_deg = 30.0; // above the horizon, degrees
    double sun_azimuth_deg = 0.0;    // 0: towards +z, 90: towards +x
    double altitude_km = 0.0;        // observer above the ground, ≥ 0
    bool sun = true;                 // the sun as a direct light
    ModelShading shading = ModelShading::Prt;
    bool sky_background = true; // the sky (network per pixel, or the reference sky's map); false: dark blue-grey
    SunShadow sun_shadow = SunShadow::Map;
    double phong_exponent = 32.0; // dprt: the Phong lobe's exponent a (> 0; higher: smoother surface)
    float specular = 0.25f;       // dprt: weight of the glossy layer, ≥ 0
    int visibility_direction = 0; // visibility: index into the light's sphere rule
    float zoom = 1.0f;            // camera distance as a multiple of preview_camera()'s, > 0
};

struct ModelFrameStats {
    std::size_t vertices = 0, triangles = 0;
    int sh_order = 0;
    ModelShading shading = ModelShading::Prt; // what was drawn (Unshadowed when the model has no transfer)
    double light_seconds = 0.0;               // sky SH projection (0 when the sun did not move)
    double sun_seconds = 0.0;                 // sun visibility or shadow map (0 when the sun did not move)
    double background_seconds = 0.0;          // the reference sky's map (0 when it did not change)
    double draw_seconds = 0.0;                // drawing until the GPU finished
};

// The exposure, in stops, that maps the 95th-percentile luminance (Rec. 709)
// of the image's non-zero pixels to 0.6; 0 for an image with none.
float model_auto_exposure_ev(const Image& linear);

// [SECTION] Rendering --------------------------------------------------------------------
// Owns a headless EGL context (or uses the caller's, InCurrentContext) and the model on the GPU. sky: the sky of the
// light (reference or network); the background needs a network
// (sky.is_network()), else it is the previews' dark blue-grey. light_rule: a
// sphere rule for the SH projection (exact to its precision). light_order:
// the SH order of the light, at least the transfer's (≤ kPrtMaxOrder); with
// no transfer, that of the unshadowed transfer. Throws skybake::Error (one
// line) when there is no headless OpenGL, a shader does not compile, the
// transfer needs more vertex attributes than the driver has ("order"), or
// for the fields of SkyProjector::project().
class ModelRenderer {
public:
    ModelRenderer(const ViewerModel& model, const SkySource& sky, const SphereRule& light_rule, int light_order);
    // The same in the OpenGL context current on the calling thread (a
    // window's, 3.3 core or newer), which must stay current during every
    // call and outlive the renderer. `model` and `sky` must outlive it too.
    struct InCurrentContext {};
    ModelRenderer(const ViewerModel& model, const SkySource& sky, const SphereRule& light_rule, int light_order,
                  InCurrentContext);
    ~ModelRenderer();
    ModelRenderer(const ModelRenderer&) = delete;
    ModelRenderer& operator=(const ModelRenderer&) = delete;

    // Linear radiance (per unit sun irradiance, as relight()), top row first,
    // camera.width × camera.height, averaged over camera.samples² samples per pixel.
    Image render(const ModelViewSettings& settings, ModelFrameStats* stats = nullptr);
    // Draws one sample per pixel into the renderer's float target and returns
    // the OpenGL name of its colour texture (GL_RGBA32F, camera.width ×
    // camera.height, linear radiance, bottom row first); for a window, which
    // tone-maps it. camera.samples is ignored.
    unsigned draw(const ModelViewSettings& settings, ModelFrameStats* stats = nullptr);
    // Linear RGB of the last draw(), top row first.
    Image read_last_draw() const;
    // Replaces the albedo (vertex_count() entries, linear RGB in [0, 1]).
    void set_albedo(std::span<const glm::vec3> albedo);
    // The same model flat-shaded (one constant colour, no sky): the benchmark's baseline.
    Image render_flat(const ModelViewSettings& settings, ModelFrameStats* stats = nullptr);
    // The SH light of the last render().
    const ShLight& light() const;
    std::string device_description() const;

    struct Impl;

private:
    std::unique_ptr<Impl> impl_;
};

// [SECTION] Window ---------------------------------------------------------------------------
// `skybake view MODEL.glb` without --screenshot: a GLFW window with a Dear
// ImGui panel (src/render/model_viewer.cpp, on the shell of
// src/render/window_shell.h shared with `skybake view planet`).
struct ModelViewerOptions {
    ModelViewSettings view;          // the starting view (camera.width × height: the window's size)
    bool auto_exposure = true;       // else exposure_ev
    float exposure_ev = 0.0f;        // stops
    int frames = 0;                  // > 0: close after this many frames (tests), else run until closed
    std::string screenshot = "skybake_view.png"; // where the screenshot key (P) writes
    std::string last_frame;          // non-empty: the window as shown (panel included) at the last frame, PNG
    std::string title = "skybake view";
    // The skies the panel offers (network / reference), outliving the call:
    // reference non-null, network may be null; start_network (with a
    // network) shows it first. The panel may replace both (an atmosphere
    // preset, a weights file).
    const SkySource* network = nullptr;
    const SkySource* reference = nullptr;
    bool start_network = true;
    SphereRule light_rule; // the SH projection's rule
    // Bakes a transfer for the model (the panel's Bake button, shown when the
    // model has none), on a worker thread: progress reported through the
    // progress callback (skybake/progress.h), cancelled by skybake::Interrupted
    // thrown from it. Empty: no button.
    std::function<ViewerModel(const ViewerModel& model)> bake;
    bool bake_at_start = false; // press the Bake button at the first frame (when the model has no transfer)
    bool panel_folded = false;  // start with the panel folded to its title bar
};
// Runs until the window is closed (or `frames` are drawn). Throws
// skybake::Error (where: "display") when there is no display or the build has
// no window (GLFW or Dear ImGui missing), and as ModelRenderer.
void run_model_viewer(const ViewerModel& model, const ModelViewerOptions& options);
// Whether this build has the window (GLFW and Dear ImGui were found).
bool viewer_window_available();

} // namespace skybake
