// libFuzzer target: glTF through skybake's reader and schema check. The
// first byte picks JSON (.gltf, even) or binary (.glb, odd); the rest is the
// file. Whatever loads must pass validate_mesh.
#include <cstddef>
#include <cstdint>

#include "skybake/error.h"
#include "skybake/mesh.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size < 1)
        return 0;
    skybake::ImportLimits limits;
    limits.max_file_bytes = 1 << 20;
    limits.max_vertices = limits.max_triangles = 1 << 20;
    try {
        const skybake::Mesh m =
            skybake::load_mesh_from_memory(data + 1, size - 1, data[0] % 2 ? "glb" : "gltf", nullptr, limits);
        skybake::validate_mesh(m);
    } catch (const skybake::Error&) {
    }
    return 0;
}
