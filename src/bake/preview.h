// Internal: the preview's camera and ray cast with a caller's shading, for
// previews that need the view direction (glossy PRT relighting).
#pragma once

#include <cstdint>
#include <functional>

#include <glm/vec3.hpp>

#include "skybake/bake.h"

namespace skybake::bake {

// shade(triangle's three vertex indices, u, v, ray direction (unit, from the
// eye)) gives a hit's linear RGB; background(ray direction), when given, a
// miss's (else the dark blue-grey of render_ao_preview()). Same camera and
// sampling as render_ao_preview(); throws skybake::Error on bad options.
using PreviewShader = std::function<glm::vec3(const std::uint32_t* triangle, float u, float v, const glm::vec3& dir)>;
using PreviewBackground = std::function<glm::vec3(const glm::vec3& dir)>;
Image render_preview(const Mesh& mesh, const AoPreviewOptions& options, const PreviewShader& shade,
                     const PreviewBackground& background = {});

} // namespace skybake::bake
