// skybake mesh convert INPUT -o OUTPUT.glb|.gltf|.ply [--ascii] [--json]
#include "cli.h"
#include "commands.h"
#include "flags.h"
#include "skybake/gltf_asset.h"
#include "skybake/mesh.h"

namespace skybake::cli {

namespace {
struct MeshConvertOptions {
    std::string input, output;
    bool ascii = false;
    bool json = false;
};

void run(const MeshConvertOptions& o) {
    check_output_path(o.output, {".glb", ".gltf", ".ply"}, "--output");
    if (o.ascii && lower_extension(o.output) != ".ply")
        throw UsageError("--ascii applies to .ply outputs only", "--ascii");
    // glTF 2.0 to glTF keeps the document whole, as the bakes do (skybake/gltf_asset.h).
    const BakeFile file = open_bake_file(o.input, o.output);
    ExportOptions e;
    e.ply_encoding = o.ascii ? PlyEncoding::Ascii : PlyEncoding::Binary;
    file.save(o.output, e);
    const Mesh& mesh = file.mesh();
    const ImportReport& rep = file.report();
    if (o.json) {
        print_json({{"input", o.input},
                    {"output", o.output},
                    {"vertices", mesh.vertex_count()},
                    {"triangles", mesh.triangle_count()},
                    {"degenerate_triangles", rep.degenerate_triangles}});
        return;
    }
    info("wrote {} ({} vertices, {} triangles)", o.output, mesh.vertex_count(), mesh.triangle_count());
}
} // namespace

void add_mesh_convert(CLI::App& group) {
    auto o = std::make_shared<MeshConvertOptions>();
    CLI::App* sub = group.add_subcommand("convert", "Read any supported mesh and write it as .glb or .ply");
    sub->add_option("input", o->input, "Input mesh")->required();
    sub->add_option("-o,--output", o->output, "Output mesh (.glb, .gltf or .ply); a glTF 2.0 input written as glTF keeps its whole document")->required();
    sub->add_flag("--ascii", o->ascii, "Write PLY as ASCII instead of binary");
    add_json_flag(*sub, o->json);
    sub->callback([o] { run(*o); });
}

SKYBAKE_CLI_COMMAND("mesh", add_mesh_convert)

} // namespace skybake::cli
