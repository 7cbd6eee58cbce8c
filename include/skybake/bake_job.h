// skybake/bake_job.h: one bake of a mesh, whatever it computes, for every
// front end (the `ao` and `prt bake` commands, Python, the viewer's Bake
// button, MPI jobs).
//
// [SECTION] The job
// [SECTION] Running it
//
// A job names what to compute at the mesh's vertices (AO, shading and bent
// normals; SH transfer with bounces; visibility bits) and at the texels of a
// UV layout (texture AO), and where to run (a TracerRequest). run_bake_job()
// resolves the device once, creates one backend, builds its acceleration
// structure once for the mesh, and runs every asked-for reduction over it:
// the vertex bake, the texture bake, the bounces' closest hits and the
// preview image reuse that structure when the backend answers ray queries.
// The ray origins are the bake driver's (skybake/bake.h) for every pass.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "skybake/bake.h"
#include "skybake/image.h"
#include "skybake/mesh.h"
#include "skybake/prt.h"
#include "skybake/sphere.h"
#include "skybake/texture_bake.h"
#include "skybake/visibility.h"

namespace skybake {

// [SECTION] The job -----------------------------------------------------------------

struct BakeJob {
    SphereRule rule;        // a sphere rule (not a Phong rule)
    TracerRequest tracer;   // device, backend, method, resolution (closest_hit is set by the job)
    BakeOptions options;    // max_distance, ray_offset, back_faces, normalize; method comes from `tracer`

    // What is computed; any combination.
    bool shading = true;    // AO, A and bent normal per vertex, stored on the mesh (bake_ambient_occlusion())
    bool bits = false;      // also keep the visibility bits (BakeJobResult::outputs.visibility_bits)
    std::optional<TransferOptions> transfer; // SH transfer per vertex, bounces included (bake_transfer())
    // The bounces' albedo, one per vertex; empty: mesh_albedo(mesh).
    std::vector<glm::vec3> albedo;
    // The base colour images (base_color_images()): bounces off a textured
    // material take the albedo at the hit's UV (bake_transfer()). Empty: per vertex only.
    std::vector<Image> albedo_images;
    std::optional<TextureBakeOptions> texture; // AO at the texels of a UV layout (bake_ao_texture())
    // A preview image of the baked AO (render_ao_preview()), or of the
    // texture AO over base_colors (render_texture_preview()) with a texture.
    std::optional<AoPreviewOptions> preview;
    std::vector<Image> base_colors; // per material, for the texture preview; may be empty

    // The backend's tracer made beforehand, by make_visibility_tracer(check_bake_job(job))
    // (so that a missing device fails before a mesh is read); or null: the job makes it.
    std::shared_ptr<VisibilityTracer> made_tracer;
    // Wraps the backend's tracer (e.g. make_distributed_tracer() for an MPI
    // job). Empty: the tracer as it is.
    std::function<std::unique_ptr<VisibilityTracer>(std::unique_ptr<VisibilityTracer>)> wrap_tracer;
};

// [SECTION] Running it --------------------------------------------------------------

struct BakeJobResult {
    TracerChoice choice;      // the resolved backend and method
    std::string device_name;  // the GPU's or the OpenGL renderer's name; empty on the CPU
    AoBakeReport ao;          // with shading
    BakeOutputs outputs;      // with shading: AO, A, bent normals (and bits)
    Transfer transfer;        // with transfer
    TransferReport transfer_report;
    std::optional<AoTexture> texture; // with texture
    Image preview;            // with preview
    // Acceleration structures built for the mesh: 1, or 2 when the preview
    // or the bounces need ray queries that the tracer's backend does not answer.
    int acceleration_structures = 0;
};

// Runs the job on `mesh` (normals are computed when it has none). Stores
// what bake_ambient_occlusion() stores (with shading) and nothing else on the
// mesh. Throws skybake::Error naming the field at fault: those of
// resolve_tracer() ("device", "backend", "method", "resolution"), "rule",
// "max_distance" (none with the directional method), the bakes' own, and
// skybake::Interrupted after SIGINT or SIGTERM. Every check that needs no
// tracing comes before the first ray.
BakeJobResult run_bake_job(Mesh& mesh, const BakeJob& job);

// The checks of run_bake_job() that need no mesh, for a front end that wants
// to fail before it reads one. Returns the resolved tracer.
TracerChoice check_bake_job(const BakeJob& job);

} // namespace skybake
