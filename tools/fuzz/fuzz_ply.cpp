// libFuzzer target: skybake's own PLY reader (ASCII and binary), through the
// same entry point as `load_mesh`. Whatever loads must pass validate_mesh.
#include <cstddef>
#include <cstdint>

#include "skybake/error.h"
#include "skybake/mesh.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    skybake::ImportLimits limits;
    limits.max_file_bytes = 1 << 20;
    limits.max_vertices = limits.max_triangles = 1 << 20;
    try {
        const skybake::Mesh m = skybake::load_mesh_from_memory(data, size, "ply", nullptr, limits);
        skybake::validate_mesh(m);
    } catch (const skybake::Error&) {
    }
    return 0;
}
