// The per-ray shading of a neural sky image, shared by the CPU and CUDA
// renderers: sky::shade_ray_approximate (src/sky/shade_shared.h) with the
// network as the sky function (seed 000, sections III and IV).
#pragma once

#include "neural/mlp_hd.h"
#include "sky/render_hd.h"

namespace skybake::neural {

using sky::shade_ray_approximate;

// The network's sky.
struct NetworkSky {
    const MlpHD& net;
    SKYBAKE_HD_INLINE glm::vec3 operator()(float cv, float cvs, float cs, float rho) const {
        return neural_sky(net, cv, cvs, cs, rho);
    }
};

SKYBAKE_HD_INLINE glm::vec3 shade_ray_neural(const sky::RenderHD& p, const MlpHD& net, const glm::vec3& d) {
    return sky::shade_ray_approximate(p, NetworkSky{net}, d);
}

} // namespace skybake::neural
