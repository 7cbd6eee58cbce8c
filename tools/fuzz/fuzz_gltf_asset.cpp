// libFuzzer target: a glTF document baked in place (GltfAsset::load, then
// save, what `ao bake` does when the input and the output are glTF). It
// keeps the document's JSON and buffers, which load_mesh() forgets. The first
// byte picks JSON (.gltf, even) or binary (.glb, odd); the rest is the file,
// written to a fixed folder per process. Whatever loads must pass
// validate_mesh; with an attribute added it must save, and what it saved
// must load again with the same vertices and that attribute.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>
#include <vector>

#include "skybake/error.h"
#include "skybake/gltf_asset.h"
#include "skybake/mesh.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    namespace fs = std::filesystem;
    if (size < 1 || size > (1 << 20))
        return 0;
    static const fs::path dir = [] {
        const fs::path d = fs::temp_directory_path() / ("skybake-fuzz-gltf-asset-" + std::to_string(getpid()));
        fs::create_directories(d);
        std::atexit([] {
            std::error_code ec;
            fs::remove_all(fs::temp_directory_path() / ("skybake-fuzz-gltf-asset-" + std::to_string(getpid())), ec);
        });
        return d;
    }();
    const std::string ext = data[0] % 2 ? ".glb" : ".gltf";
    const fs::path in = dir / ("in" + ext), out = dir / ("out" + ext);
    {
        std::ofstream f(in, std::ios::binary | std::ios::trunc);
        f.write(reinterpret_cast<const char*>(data + 1), std::streamsize(size - 1));
    }
    skybake::ImportLimits limits;
    limits.max_file_bytes = 1 << 20;
    limits.max_vertices = limits.max_triangles = 1 << 20;
    limits.isolate_parsers = false;
    try {
        skybake::GltfAsset asset = skybake::GltfAsset::load(in, limits);
        skybake::Mesh& mesh = asset.mesh();
        skybake::validate_mesh(mesh);
        const std::size_t n = mesh.vertex_count();
        mesh.set_attribute("ao", 1, std::vector<float>(n, 0.5f));
        bool saved = false;
        try {
            asset.save(out);
            saved = true;
        } catch (const skybake::Error&) {
        }
        if (saved) {
            const skybake::GltfAsset back = skybake::GltfAsset::load(out, limits);
            const skybake::VertexAttribute* ao = back.mesh().find_attribute("ao");
            if (back.mesh().vertex_count() != n || (n > 0 && (!ao || ao->values.size() != n)))
                std::abort(); // what save() wrote does not read back
        }
    } catch (const skybake::Error&) {
    }
    std::error_code ec;
    fs::remove(out, ec);
    return 0;
}
