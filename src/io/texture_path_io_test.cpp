// Texture paths written on another machine (backslashes, drive letters,
// absolute paths): found beside the model, or reported as missing; never
// written out as they came. Labelled "io".
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "io/texture_path.h"
#include "skybake/files.h"
#include "skybake/mesh.h"
#include "core/test_paths.h"

using namespace skybake;
namespace fs = std::filesystem;

namespace {

const fs::path kModels = skybake::test::assimp_models();

fs::path temp_folder(const std::string& name) {
    const fs::path dir = fs::temp_directory_path() / ("skybake-texpath-test-" + std::to_string(::getpid())) / name;
    fs::create_directories(dir);
    return dir;
}

} // namespace

TEST(TexturePath, FoundAsWrittenOrByItsTrailingFolders) {
    const fs::path root = temp_folder("find");
    fs::create_directories(root / "models" / "FBX");
    fs::create_directories(root / "models" / "OBJ");
    fs::create_directories(root / "models" / "FBX" / "tex");
    std::ofstream(root / "models" / "OBJ" / "wood.jpg") << "x";
    std::ofstream(root / "models" / "FBX" / "tex" / "paint.png") << "x";
    const fs::path dir = root / "models" / "FBX";
    // As written, relative to the model, with either separator.
    EXPECT_EQ(io::find_texture("tex/paint.png", dir), (dir / "tex" / "paint.png").lexically_normal());
    EXPECT_EQ(io::find_texture("tex\\paint.png", dir), (dir / "tex" / "paint.png").lexically_normal());
    EXPECT_EQ(io::find_texture("..\\OBJ\\wood.jpg", dir), (root / "models" / "OBJ" / "wood.jpg").lexically_normal());
    // Absolute on another machine: the trailing folders, under the model's folder or the one above.
    EXPECT_EQ(io::find_texture("D:\\work\\models\\OBJ\\wood.jpg", dir),
              (root / "models" / "OBJ" / "wood.jpg").lexically_normal());
    EXPECT_EQ(io::find_texture("C:/art/tex/paint.png", dir), (dir / "tex" / "paint.png").lexically_normal());
    EXPECT_EQ(io::find_texture("/home/someone/paint.png", dir), std::nullopt); // not in a folder looked at
    EXPECT_EQ(io::find_texture("/home/someone/tex/paint.png", dir), (dir / "tex" / "paint.png").lexically_normal());
    // Nowhere.
    EXPECT_EQ(io::find_texture("D:\\work\\missing.jpg", dir), std::nullopt);
    EXPECT_EQ(io::find_texture("", dir), std::nullopt);
    EXPECT_EQ(io::find_texture("tex/paint.png", fs::path()), std::nullopt);
    // An absolute path that exists here is taken as it is.
    const fs::path abs = fs::absolute(dir / "tex" / "paint.png");
    EXPECT_EQ(io::find_texture(abs.string(), fs::path()), abs.lexically_normal());
}

// spider.fbx names its images as "D:\projects\assimp_int\test\models\OBJ\*.jpg";
// the images ship in models/OBJ/. Each is found and embedded in the .glb
// written from it, once per file; moved elsewhere, the .glb still has them.
TEST(TexturePath, SpiderFbxTexturesAreFoundAndWrittenPortably) {
    const fs::path spider = kModels / "FBX" / "spider.fbx";
    ImportReport report;
    const Mesh mesh = load_mesh(spider, &report);
    EXPECT_TRUE(report.missing_textures.empty()) << report.missing_textures.front();
    std::size_t textured = 0;
    for (const MeshMaterial& m : mesh.materials) {
        if (m.base_color_texture.empty())
            continue;
        ++textured;
        EXPECT_EQ(m.base_color_texture.find('\\'), std::string::npos) << m.base_color_texture;
        EXPECT_TRUE(fs::is_regular_file(m.base_color_texture)) << m.base_color_texture;
        EXPECT_EQ(fs::path(m.base_color_texture).parent_path().filename(), "OBJ") << m.base_color_texture;
    }
    EXPECT_GE(textured, 3u);

    const fs::path out = temp_folder("spider") / "spider.glb";
    save_mesh(out, mesh);
    const std::string data = read_file(out);
    std::uint32_t len;
    std::memcpy(&len, data.data() + 12, 4);
    const auto j = nlohmann::json::parse(data.substr(20, len));
    ASSERT_TRUE(j.contains("images"));
    std::set<std::string> files;
    for (const MeshMaterial& m : mesh.materials)
        if (!m.base_color_texture.empty())
            files.insert(m.base_color_texture);
    EXPECT_EQ(j["images"].size(), files.size()) << "one image per file";
    for (const auto& image : j["images"]) {
        EXPECT_FALSE(image.contains("uri")) << image.dump();
        EXPECT_EQ(image["mimeType"], "image/jpeg");
        EXPECT_TRUE(image.contains("bufferView"));
    }
    EXPECT_EQ(j["textures"].size(), j["images"].size());
    const fs::path moved = temp_folder("spider-moved") / "spider.glb";
    fs::rename(out, moved);
    const Mesh back = load_mesh(moved);
    ASSERT_EQ(back.materials.size(), mesh.materials.size()); // (unused vertices are not written)
    for (std::size_t i = 0; i < mesh.materials.size(); ++i) // the files' bytes travel with the .glb
        if (!mesh.materials[i].base_color_texture.empty())
            EXPECT_EQ(std::string(back.materials[i].base_color_image.begin(), back.materials[i].base_color_image.end()),
                      read_file(mesh.materials[i].base_color_texture));
}

// Moved away from its images: each is reported (as the file spells it), the
// materials keep their colours and carry no texture.
TEST(TexturePath, MissingTexturesAreReportedNotWritten) {
    const fs::path dir = temp_folder("alone");
    const fs::path spider = dir / "spider.fbx";
    fs::copy_file(kModels / "FBX" / "spider.fbx", spider, fs::copy_options::overwrite_existing);
    ImportReport report;
    const Mesh mesh = load_mesh(spider, &report);
    ASSERT_GE(report.missing_textures.size(), 3u);
    std::set<std::string> once;
    for (const std::string& t : report.missing_textures) {
        EXPECT_NE(t.find(".jpg"), std::string::npos) << t;
        EXPECT_TRUE(once.insert(t).second) << t << " reported twice";
    }
    for (const MeshMaterial& m : mesh.materials)
        EXPECT_TRUE(m.base_color_texture.empty()) << m.base_color_texture;
}

// A model named by its bare file name, from its own folder: its images are
// beside it (the folder is ".", not none).
TEST(TexturePath, ModelInTheCurrentFolderFindsItsImages) {
    const fs::path dir = temp_folder("here");
    for (const auto& e : fs::directory_iterator(kModels / "glTF" / "CesiumMilkTruck"))
        fs::copy_file(e.path(), dir / e.path().filename(), fs::copy_options::overwrite_existing);
    const fs::path before = fs::current_path();
    fs::current_path(dir);
    ImportReport report;
    Mesh mesh;
    try {
        mesh = load_mesh("CesiumMilkTruck.gltf", &report);
    } catch (...) {
        fs::current_path(before);
        throw;
    }
    fs::current_path(before);
    EXPECT_TRUE(report.missing_textures.empty()) << report.missing_textures.front();
    std::size_t textured = 0;
    for (const MeshMaterial& m : mesh.materials)
        textured += !m.base_color_texture.empty();
    EXPECT_EQ(textured, 2u);
}
