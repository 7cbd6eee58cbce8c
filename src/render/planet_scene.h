// The GL resources of the planet renderer for the current context: programs,
// the tables texture, the weights' uniform buffer, the sky shell and the
// planet mesh's buffers. Shared by the headless renderer and the viewer.
#pragma once

#include <vector>

#include <glm/mat4x4.hpp>

#include "gl/gl.h"
#include "skybake/render.h"

namespace skybake::render {

using namespace skybake::gl; // the OpenGL layer

class PlanetScene {
public:
    // Needs `context` current; keeps a reference to `model`.
    PlanetScene(const GlContext& context, const SkyModel& model, const NeuralSky* net,
                const PlanetRenderOptions& options);
    ~PlanetScene();

    // CLOD update for the view and upload of the camera-relative mesh.
    void update_mesh(const PlanetView& view, PlanetFrameStats* stats);
    // Draws into the bound framebuffer (linear radiance; flat: the baseline shading).
    void draw(const PlanetView& view, bool flat, PlanetFrameStats* stats);
    // Tone-maps a linear float texture into the bound framebuffer (sRGB values).
    void tone_map(GLuint texture, int width, int height, float exposure_ev, ToneCurve curve);
    const PlanetRenderOptions& options() const { return options_; }

private:
    struct Basis {
        glm::vec3 forward, right, up;
        float tan_half_fov;
        glm::mat4 view_proj;
    };
    Basis basis(const PlanetView& v) const;
    PlanetCamera clod_camera(const PlanetView& v, const Basis& b) const;
    glm::dvec3 geometric_eye(const PlanetView& v) const;
    glm::dvec3 shading_eye(const PlanetView& v) const;
    void set_uniforms(GLuint program, const PlanetView& v, const Basis& b) const;

    PlanetRenderOptions options_;
    const SkyModel& model_;
    bool clip_control_;
    PlanetMesh mesh_;
    Program sky_, planet_, flat_, tone_;
    Buffer weights_;
    Texture tables_;
    int rows_ = 0, cols_ = 0;
    // Multiple scattering: the SkyModel's tables in one R32F buffer texture (unit 1).
    Buffer ms_buf_;
    Texture ms_tex_;
    int ms_psi_first_ = 0, ms_irr_first_ = 0;
    VertexArray empty_vao_, dome_vao_, mesh_vao_;
    Buffer dome_vbo_, dome_ibo_, pos_vbo_, nrm_vbo_, mesh_ibo_;
    VertexArray shell_vao_;
    Buffer shell_vbo_, shell_ibo_;
    std::vector<double> dome_rings_; // ring angles above the horizon, degrees, 0 to 180
    int dome_azimuths_ = 96;
    std::vector<glm::vec3> dome_dirs_;
    std::vector<glm::dvec3> shell_dirs_; // unit directions of the top-of-atmosphere shell
    std::vector<float> shell_rel_;       // its vertices relative to the eye, km
    GLsizei dome_count_ = 0, mesh_count_ = 0, shell_count_ = 0;
    std::vector<std::uint32_t> indices_;
    std::vector<float> positions_, normals_;
};

} // namespace skybake::render
