// A bake's mesh and the file it came from (skybake/gltf_asset.h, [SECTION]
// A bake's file).
#include <fmt/format.h>

#include "skybake/error.h"
#include "skybake/gltf_asset.h"
#include "skybake/mesh.h"

namespace skybake {

namespace {

std::string lower_extension(const std::filesystem::path& p) {
    std::string e = p.extension().string();
    for (char& c : e)
        c = char(std::tolower(static_cast<unsigned char>(c)));
    return e;
}

} // namespace

BakeFile::BakeFile() = default;
BakeFile::BakeFile(BakeFile&&) noexcept = default;
BakeFile& BakeFile::operator=(BakeFile&&) noexcept = default;
BakeFile::~BakeFile() = default;

BakeFile BakeFile::open(const std::filesystem::path& input, const std::filesystem::path& output,
                        const ImportLimits& limits) {
    const std::string out = lower_extension(output);
    BakeFile f;
    if (out != ".ply" && GltfAsset::is_gltf2(input, limits)) {
        f.asset_ = std::make_unique<GltfAsset>(GltfAsset::load(input, limits));
        f.report_ = f.asset_->report();
        return f;
    }
    if (out == ".gltf")
        throw Error("a .gltf output keeps a glTF 2.0 input's document; write other inputs as .glb", "output");
    f.plain_ = load_mesh(input, &f.report_, limits);
    return f;
}

Mesh& BakeFile::mesh() { return asset_ ? asset_->mesh() : plain_; }
const Mesh& BakeFile::mesh() const { return asset_ ? asset_->mesh() : plain_; }
const ImportReport& BakeFile::report() const { return report_; }
GltfAsset* BakeFile::document() { return asset_.get(); }

void BakeFile::save(const std::filesystem::path& output, const ExportOptions& options) const {
    if (asset_)
        asset_->save(output);
    else
        save_mesh(output, plain_, options);
}

} // namespace skybake
