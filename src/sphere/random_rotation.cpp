// Host entry point of the per-vertex random rotation (maths in random_rotation.h).
#include "sphere/random_rotation.h"

#include "skybake/sphere.h"

namespace skybake {

glm::dmat3 vertex_rotation(std::uint32_t vertex, std::uint64_t seed) {
    return sphere::vertex_rotation_hd<double>(vertex, seed);
}

} // namespace skybake
