// Internal: the Embree 3 visibility backend. Exposed to the benchmarks, which
// compare the bake against bare Embree loops on the same scene.
#pragma once

#include <mutex>
#include <string>
#include <vector>

#include <embree3/rtcore.h>
#include <glm/vec3.hpp>

#include "skybake/visibility.h"

namespace skybake::visibility {

class EmbreeBackend final : public RayQueries, public VisibilityTracer {
public:
    EmbreeBackend();
    ~EmbreeBackend() override;
    EmbreeBackend(const EmbreeBackend&) = delete;
    EmbreeBackend& operator=(const EmbreeBackend&) = delete;

    const char* name() const override { return "embree"; }
    void set_mesh(const Mesh& mesh, BackFaces back_faces) override;
    void occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded) const override;
    void intersect(std::span<const Ray> rays, std::span<RayHit> hits) const override;
    std::uint32_t set_rule(const TraceRule& rule) override;
    void trace(const TraceChunk& chunk) override;

    // The committed scene (nullptr before set_mesh), for benchmarks.
    RTCScene scene() const { return scene_; }

private:
    static void error_callback(void* self, RTCError code, const char* message);
    static void back_face_filter(const RTCFilterFunctionNArguments* args);
    void check(const char* what);

    RTCDevice device_ = nullptr;
    RTCScene scene_ = nullptr;
    std::vector<glm::vec3> face_normals_; // front side, for BackFaces::Ignore
    TraceRule rule_;
    std::vector<float> fixed_x_, fixed_y_, fixed_z_; // the rule's directions, visiting order
    std::mutex error_mutex_;
    std::string last_error_;
};

} // namespace skybake::visibility
