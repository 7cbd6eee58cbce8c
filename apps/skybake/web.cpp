// skybake web: a static site that shows a baked model under the neural sky
// in any browser with WebGL 2, from file:// or any web server.
//
// SITE/index.html, SITE/skybake-site.js (three.js and skybake-web, bundled by
// esbuild when skybake is built; web/site/app.js) and SITE/data.js: the
// model (.glb, base64), the weights file, the network's GLSL ES export and,
// for a model from `prt bake`, the transfer's GLSL ES export and layout.
// data.js is a script, not files to fetch, because browsers refuse fetch()
// on file://. --serve then serves the folder on 127.0.0.1 with Python's
// http.server (in the foreground; Ctrl-C stops it).
#include <algorithm>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>

#include <nlohmann/json.hpp>

#include "cli.h"
#include "commands.h"
#include "flags.h"
#include "skybake/files.h"
#include "skybake/gltf_asset.h"
#include "skybake/mesh.h"
#include "skybake/neural.h"
#include "skybake/prt.h"

#ifndef SKYBAKE_WEB_SITE_DIR
#define SKYBAKE_WEB_SITE_DIR ""
#endif

namespace skybake::cli {

namespace {

namespace fs = std::filesystem;

// The built page: SKYBAKE_WEB_SITE_DIR (the build's web/site folder), else
// share/skybake/web beside the executable's prefix.
fs::path site_dir() {
    std::vector<fs::path> candidates;
    if (const char* env = std::getenv("SKYBAKE_WEB_SITE_DIR"))
        candidates.emplace_back(env);
    if (*SKYBAKE_WEB_SITE_DIR)
        candidates.emplace_back(SKYBAKE_WEB_SITE_DIR);
    for (const fs::path& d : candidates)
        if (fs::exists(d / "skybake-site.js") && fs::exists(d / "index.html"))
            return d;
    throw Error("the web page was not built with this skybake (it needs node and npm at build time: "
                "scripts/install-deps.sh, then cmake -DSKYBAKE_WEB=ON)");
}

void add_web(CLI::App& app) {
    struct Opts {
        std::string model, weights, output;
        bool serve = false;
        int port = 8000;
    };
    auto o = std::make_shared<Opts>();
    app.add_option("model", o->model, "A .glb: from `prt bake` (PRT shading), `ao` (AO shading) or any other")->required();
    app.add_option("--model", o->weights, "Weights file of the neural sky (JSON from `skybake sky train`)")->required();
    app.add_option("-o,--output", o->output, "Folder of the site (created; files in it are replaced)")->required();
    app.add_flag("--serve", o->serve, "Then serve the folder on http://127.0.0.1:PORT/ until interrupted (python3's http.server)");
    app.add_option("--port", o->port, "Port of --serve")->check(CLI::Range(1, 65535))->capture_default_str();
    app.callback([o] {
        if (fs::path(o->model).extension() != ".glb")
            throw UsageError(fmt::format("'{}' is not a .glb (`skybake mesh convert` writes one)", o->model), "model");
        const fs::path dir = site_dir();
        const NeuralSky net = load_neural_sky(o->weights);
        const std::string sky_glsl = export_neural_sky(net, ExportLanguage::GlslEs);
        const std::string glb = read_file(o->model);
        // The model is read once here, so that a corrupt or empty file fails
        // now with its reason rather than later on the page.
        nlohmann::json prt = nullptr;
        std::string shading = "sun only";
        if (!fs::exists(prt_sidecar_path(o->model))) {
            const Mesh mesh = load_mesh(o->model);
            // The page's order: _AO, COLOR_0, then an occlusion texture (a
            // material's occlusionTexture, which load_mesh() does not keep)
            // that the mesh has the UV set for.
            bool texture_ao = false;
            const auto doc = nlohmann::json::parse(glb_json_chunk(glb, o->model), nullptr, false);
            if (doc.is_object() && doc.contains("materials") && doc["materials"].is_array())
                for (const auto& m : doc["materials"])
                    if (m.is_object() && m.contains("occlusionTexture") && m["occlusionTexture"].is_object())
                        texture_ao |= std::size_t(m["occlusionTexture"].value("texCoord", 0)) < mesh.texcoords.size();
            if (mesh.find_attribute("ao") || !mesh.colors.empty() || texture_ao)
                shading = "AO";
        } else {
            shading = "PRT";
            const PrtModel m = load_prt(o->model);
            PrtShaderOptions so;
            so.es = true;
            const int count = (m.transfer.order + 1) * (m.transfer.order + 1);
            prt = {{"glsl", export_prt_glsl(m.transfer.order, m.transfer.channels, so)},
                   {"order", m.transfer.order},
                   {"channels", m.transfer.channels},
                   {"attributes", (m.transfer.channels * count + 3) / 4}};
        }
        const std::string weights = read_file(o->weights); // JSON, checked by load_neural_sky above
        OutputFolder folder(o->output, "--output");
        const fs::path out(o->output);
        write_stream_atomic(out / "data.js", [&](std::ostream& f) {
            f << "// Written by `skybake web`: the model, the neural sky and their shaders.\nwindow.SKYBAKE_SITE = {\n"
              << "model: \"" << base64_encode(glb) << "\",\nweights: " << weights << ",\nskyGlsl: "
              << nlohmann::json(sky_glsl).dump() << ",\nprt: " << prt.dump() << "\n};\n";
        });
        for (const char* name : {"index.html", "skybake-site.js"}) {
            const std::string text = read_file(dir / name);
            write_stream_atomic(out / name, [&](std::ostream& f) { f << text; });
        }
        folder.keep();
        info("{} ({} shading, {} KiB) under {} ({} weights) -> {}", o->model, shading,
             glb.size() / 1024, net.atmosphere.name, net.topology.weight_count(), (out / "index.html").string());
        if (!o->serve)
            return;
        const std::string port = std::to_string(o->port), folder_arg = out.string();
        fmt::print("serving {} at http://127.0.0.1:{}/ (Ctrl-C stops)\n", folder_arg, port);
        std::fflush(stdout);
        const char* argv[] = {"python3", "-m", "http.server", port.c_str(), "--bind", "127.0.0.1", "--directory",
                              folder_arg.c_str(), nullptr};
        execvp("python3", const_cast<char* const*>(argv));
        throw Error(fmt::format("cannot run python3 to serve the site: {}", std::strerror(errno)), "--serve");
    });
}

} // namespace

SKYBAKE_CLI_GROUP_COMMAND("web", add_web)

} // namespace skybake::cli
