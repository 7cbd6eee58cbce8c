// One bake job for every front end (skybake/bake_job.h).
#include "skybake/bake_job.h"

#include <cmath>

#include <fmt/format.h>

#include "skybake/error.h"

namespace skybake {

namespace {

// The job's backend: one tracer, and its ray queries when the same object
// answers them, sharing one acceleration structure. set_mesh() builds it on
// the first call for a mesh and does nothing on the next ones, so that the
// driver's passes (vertices, texels) and the bounces reuse it.
class SharedBackend final : public VisibilityTracer, public RayQueries {
public:
    SharedBackend(std::shared_ptr<VisibilityTracer> tracer, RayQueries* queries, int& builds)
        : tracer_(std::move(tracer)), queries_(queries), builds_(builds) {}

    const char* name() const override { return tracer_->name(); }
    TraceMethod method() const override { return tracer_->method(); }
    std::string device_name() const override { return tracer_->device_name(); }
    void set_mesh(const Mesh& mesh, BackFaces back_faces) override {
        if (mesh_ == &mesh && back_faces_ == back_faces && vertices_ == mesh.vertex_count())
            return;
        tracer_->set_mesh(mesh, back_faces);
        mesh_ = &mesh;
        back_faces_ = back_faces;
        vertices_ = mesh.vertex_count();
        builds_ += tracer_->structures_per_mesh();
    }
    std::uint32_t set_rule(const TraceRule& rule) override { return tracer_->set_rule(rule); }
    void trace(const TraceChunk& chunk) override { tracer_->trace(chunk); }
    bool device_words_supported() const override { return tracer_->device_words_supported(); }
    const std::uint32_t* device_words() const override { return tracer_->device_words(); }
    bool prefers_large_chunks() const override { return tracer_->prefers_large_chunks(); }
    int structures_per_mesh() const override { return tracer_->structures_per_mesh(); }

    bool answers_queries() const { return queries_ != nullptr; }
    // Whether the structure holds `mesh` with both sides occluding (as the preview casts).
    bool holds(const Mesh& mesh, BackFaces back_faces) const {
        return mesh_ == &mesh && back_faces_ == back_faces && vertices_ == mesh.vertex_count();
    }
    void occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded) const override {
        queries_->occluded(rays, occluded);
    }
    void intersect(std::span<const Ray> rays, std::span<RayHit> hits) const override {
        queries_->intersect(rays, hits);
    }

private:
    std::shared_ptr<VisibilityTracer> tracer_;
    RayQueries* queries_;
    int& builds_;
    const Mesh* mesh_ = nullptr;
    BackFaces back_faces_ = BackFaces::Occlude;
    std::size_t vertices_ = 0;
};

} // namespace

TracerChoice check_bake_job(const BakeJob& job) {
    if (job.rule.kind == RuleKind::Phong)
        throw Error(fmt::format("'{}' integrates against a Phong lobe, not over the sphere; use a lebedev, design, "
                                "fibonacci or mc rule for a bake",
                                job.rule.spec),
                    "rule");
    if (!job.shading && !job.transfer && !job.texture)
        throw Error("the job computes nothing: ask for shading, a transfer or a texture", "shading");
    if (job.preview && !job.shading && !job.texture)
        throw Error("a preview shows the baked AO: ask for shading or a texture too", "preview");
    TracerRequest request = job.tracer;
    request.closest_hit = job.transfer && job.transfer->kind == TransferKind::Interreflected;
    const TracerChoice c = resolve_tracer(request);
    if (c.method == TraceMethod::Directional && std::isfinite(job.options.max_distance))
        throw Error("the directional method has no maximum distance; use the cube method", "max_distance");
    if (c.method == TraceMethod::Directional && job.rule.rotate_per_vertex)
        throw Error(fmt::format("the directional method needs one set of directions for every vertex; drop "
                                "+rotate from '{}', or use the cube method",
                                job.rule.spec),
                    "rule");
    return c;
}

BakeJobResult run_bake_job(Mesh& mesh, const BakeJob& job) {
    BakeJobResult r;
    r.choice = check_bake_job(job);
    std::shared_ptr<VisibilityTracer> inner = job.made_tracer;
    if (!inner)
        inner = make_visibility_tracer(r.choice);
    else if (std::string(inner->name()) != r.choice.backend->name || inner->method() != r.choice.method)
        throw Error(fmt::format("the tracer made beforehand is {} {}, not the job's {} {}", inner->name(),
                                trace_method_name(inner->method()), r.choice.backend->name,
                                trace_method_name(r.choice.method)),
                    "made_tracer");
    RayQueries* same = r.choice.backend->closest_hit ? dynamic_cast<RayQueries*>(inner.get()) : nullptr;
    auto shared = std::make_unique<SharedBackend>(std::move(inner), same, r.acceleration_structures);
    SharedBackend& backend = *shared;
    // The bakes trace through the wrapper (an MPI job's, which the driver
    // recognises), the bounces and the preview query the backend itself.
    std::unique_ptr<VisibilityTracer> wrapped = job.wrap_tracer ? job.wrap_tracer(std::move(shared)) : std::move(shared);
    VisibilityTracer& tracer = *wrapped;
    r.device_name = backend.device_name();

    BakeOptions options = job.options;
    options.method = r.choice.method;
    options.store_bits = job.bits;
    if (mesh.normals.empty())
        compute_normals(mesh);

    // The texture first: its checks of the UV layout come before the long work.
    if (job.texture)
        r.texture = bake_ao_texture(mesh, job.rule, tracer, options, *job.texture);
    if (job.shading)
        r.ao = bake_ambient_occlusion(mesh, job.rule, tracer, options, &r.outputs);
    if (job.transfer) {
        // The bounces' closest hits: the backend's own structure when it answers them.
        std::unique_ptr<RayQueries> own;
        RayQueries* queries = nullptr;
        if (job.transfer->kind == TransferKind::Interreflected) {
            if (backend.answers_queries()) {
                queries = &backend;
            } else {
                own = make_ray_queries(r.choice);
                queries = own.get();
                ++r.acceleration_structures;
            }
        }
        const std::vector<glm::vec3> albedo = job.albedo.empty() ? mesh_albedo(mesh) : job.albedo;
        BakeOptions t = options;
        t.store_bits = false;
        r.transfer_report = bake_transfer(mesh, job.rule, tracer, t, *job.transfer, albedo, queries, r.transfer,
                                          job.albedo_images);
    }
    if (job.preview) {
        AoPreviewOptions p = *job.preview;
        if (backend.answers_queries() && backend.holds(mesh, BackFaces::Occlude))
            p.queries = &backend;
        else
            ++r.acceleration_structures; // the preview's own Embree scene
        if (r.texture)
            r.preview = render_texture_preview(mesh, *r.texture, job.texture->uv_set, job.base_colors, p);
        else
            r.preview = render_ao_preview(mesh, p);
    }
    return r;
}

} // namespace skybake
