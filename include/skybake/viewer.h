// skybake/viewer.h: a model lit by the sky in real time (OpenGL 3.3 core or
// newer), the renderer behind `skybake view MODEL.glb`. No GL types here.
//
// [SECTION] Model
// [SECTION] Settings
// [SECTION] Headless rendering
//
// Each frame: the background is the sky network evaluated per pixel (the GLSL
// of `skybake sky export`, weights in a uniform block); the model's vertices
// are lit by the sky's SH (SkyProjector, recomputed when the sun or the
// altitude moves) through a per-vertex transfer with the GLSL of
// export_prt_glsl(), plus the sun as a direct light of the transmitted
// irradiance, shadowed per vertex by one occlusion ray (sun_visibility()).
// This is relight() of skybake/prt.h evaluated on the GPU, seen through the
// camera of the ray-cast previews (preview_camera()); the tests hold the two
// to PSNR ≥ 30 dB. See docs/viewer.md.
#pragma once

#include <filesystem>
#include <memory>
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
//   unshadowed  unshadowed irradiance: T_lm = (Â_l / π) Y_lm(n).
enum class ModelShading : int { Prt = 0, Ao = 1, A = 2, Unshadowed = 3 };
// "prt", "ao", "a", "unshadowed".
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

struct ModelViewSettings {
    AoPreviewOptions camera;         // size, azimuth, elevation, field of view, samples per pixel axis
    double sun_elevation_deg = 30.0; // above the horizon, degrees
    double sun_azimuth_deg = 0.0;    // 0: towards +z, 90: towards +x
    double altitude_km = 0.0;        // observer above the ground, ≥ 0
    bool sun = true;                 // the sun as a direct light
    ModelShading shading = ModelShading::Prt;
    bool sky_background = true; // the network per pixel; false: the previews' dark blue-grey
};

struct ModelFrameStats {
    std::size_t vertices = 0, triangles = 0;
    int sh_order = 0;
    ModelShading shading = ModelShading::Prt; // what was drawn (Unshadowed when the model has no transfer)
    double light_seconds = 0.0;               // sky SH projection (0 when the sun did not move)
    double sun_seconds = 0.0;                 // per-vertex sun visibility (0 when the sun did not move)
    double draw_seconds = 0.0;                // drawing until the GPU finished
};

// [SECTION] Headless rendering ---------------------------------------------------------
// Owns a headless EGL context and the model on the GPU. sky: the sky of the
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
    ~ModelRenderer();
    ModelRenderer(const ModelRenderer&) = delete;
    ModelRenderer& operator=(const ModelRenderer&) = delete;

    // Linear radiance (per unit sun irradiance, as relight()), top row first,
    // camera.width × camera.height, averaged over camera.samples² samples per pixel.
    Image render(const ModelViewSettings& settings, ModelFrameStats* stats = nullptr);
    // The same model flat-shaded (one constant colour, no sky): the benchmark's baseline.
    Image render_flat(const ModelViewSettings& settings, ModelFrameStats* stats = nullptr);
    // The SH light of the last render().
    const ShLight& light() const;
    std::string device_description() const;

    struct Impl;

private:
    std::unique_ptr<Impl> impl_;
};

} // namespace skybake
