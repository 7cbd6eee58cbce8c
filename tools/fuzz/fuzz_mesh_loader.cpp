// libFuzzer target for the mesh loader.
//
// The first byte of the input picks the reader (PLY, GLB, glTF, OBJ, OFF,
// STL); the rest is the file. Any exception other than skybake::Error, any
// crash, leak or sanitizer report is a bug. Build and run with
// tools/fuzz/run.sh (clang, -fsanitize=fuzzer,address,undefined).
#include <cstddef>
#include <cstdint>

#include "skybake/error.h"
#include "skybake/mesh.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const char* kFormats[] = {"ply", "glb", "gltf", "obj", "off", "stl"};
    if (size < 1)
        return 0;
    const char* ext = kFormats[data[0] % (sizeof(kFormats) / sizeof(kFormats[0]))];
    skybake::ImportLimits limits;
    limits.max_file_bytes = 1 << 20;
    limits.max_vertices = 1 << 20;
    limits.max_triangles = 1 << 20;
    try {
        skybake::Mesh m = skybake::load_mesh_from_memory(data + 1, size - 1, ext, nullptr, limits);
        skybake::validate_mesh(m); // whatever loads must satisfy the invariants
    } catch (const skybake::Error&) {
    }
    return 0;
}
