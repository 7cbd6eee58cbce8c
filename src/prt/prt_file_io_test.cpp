// Transfer files (skybake/prt.h, [SECTION] Files): attributes and sidecar
// round trip through glTF and PLY, and the refusals of a bad sidecar.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <tuple>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "skybake/error.h"
#include "skybake/files.h"
#include "skybake/prt.h"
#include "skybake/image_io.h"

namespace skybake {
namespace {

struct TempDir {
    std::filesystem::path path;
    TempDir() {
        path = std::filesystem::temp_directory_path() /
               ("skybake_prt_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
                ::testing::UnitTest::GetInstance()->current_test_info()->name());
        std::filesystem::remove_all(path);
        std::filesystem::create_directories(path);
    }
    ~TempDir() { std::filesystem::remove_all(path); }
};

Transfer make_transfer(std::size_t n, int order, int channels) {
    Transfer t;
    t.order = order;
    t.coefficients = sh_count(order);
    t.channels = channels;
    t.kind = channels == 3 ? TransferKind::Interreflected : TransferKind::Shadowed;
    t.bounces = channels == 3 ? 2 : 0;
    t.rule = "lebedev:50";
    for (std::size_t i = 0; i < n * std::size_t(channels * t.coefficients); ++i)
        t.coeffs.push_back(float(i % 97) * 0.01f - 0.3f);
    return t;
}

void write(const std::filesystem::path& mesh_path, Mesh mesh, const Transfer& t) {
    const std::vector<glm::vec3> albedo(mesh.vertex_count(), glm::vec3(0.2f, 0.4f, 0.6f));
    set_transfer_attributes(mesh, t, albedo);
    save_mesh(mesh_path, mesh);
    const std::string json = transfer_sidecar_json(t, mesh.vertex_count(), "vertex-colors");
    write_stream_atomic(prt_sidecar_path(mesh_path), [&](std::ostream& o) { o << json; });
}

std::string load_error(const std::filesystem::path& p) {
    try {
        load_prt(p);
    } catch (const Error& e) {
        return e.where();
    }
    return "no error";
}

TEST(PrtFile, RoundTripGlbAndPly) {
    TempDir dir;
    ProceduralOptions o;
    o.target_triangles = 100;
    const Mesh mesh = generate_mesh(o);
    for (const char* ext : {".glb", ".ply"})
        for (int channels : {1, 3}) {
            const Transfer t = make_transfer(mesh.vertex_count(), 3, channels);
            const auto path = dir.path / fmt::format("m{}{}", channels, ext);
            write(path, mesh, t);
            EXPECT_EQ(prt_sidecar_path(path).extension(), ".json");
            const PrtModel m = load_prt(path);
            EXPECT_EQ(m.transfer.order, 3);
            EXPECT_EQ(m.transfer.channels, channels);
            EXPECT_EQ(m.transfer.kind, t.kind);
            EXPECT_EQ(m.transfer.coeffs, t.coeffs) << ext;
            ASSERT_EQ(m.albedo.size(), mesh.vertex_count());
            EXPECT_FLOAT_EQ(m.albedo[3].y, 0.4f);
        }
}

TEST(PrtFile, BadSidecars) {
    TempDir dir;
    ProceduralOptions o;
    o.target_triangles = 100;
    const Mesh mesh = generate_mesh(o);
    const auto path = dir.path / "m.glb";
    const auto side = prt_sidecar_path(path);
    save_mesh(path, mesh);
    EXPECT_EQ(load_error(path), "sidecar"); // none
    write(path, mesh, make_transfer(mesh.vertex_count(), 3, 1));
    EXPECT_EQ(load_error(path), "no error");
    const std::string good = read_file(side);
    auto with = [&](const std::string& text) {
        std::ofstream(side, std::ios::binary) << text;
        return load_error(path);
    };
    EXPECT_EQ(with("{\"format\": \"skybake-prt\", "), "sidecar"); // corrupt
    EXPECT_EQ(with("[1, 2, 3]"), "sidecar");                      // not an object
    std::string s = good;
    s.replace(s.find("\"order\": 3"), 10, "\"order\": 4");
    EXPECT_EQ(with(s), "sidecar"); // order ≠ coefficients
    s = good;
    s.replace(s.find("\"vertices\": "), 12, "\"vertices\": 1");
    EXPECT_EQ(with(s), "sidecar"); // vertex count
    s = good;
    s.replace(s.find("shadowed"), 8, "glossyyy");
    EXPECT_EQ(with(s), "sidecar"); // kind
    // A sidecar that matches another mesh: the attributes are missing.
    save_mesh(path, mesh);
    EXPECT_EQ(with(good), "sidecar");
}

TEST(PrtFile, RadianceHdrMapIsALight) {
    TempDir dir;
    // A 4x2 Radiance RGBE file (flat pixels, no run-length encoding below
    // width 8): every pixel (128, 128, 128, 129) = 0.5 · 2^1 = 1.0.
    const auto path = dir.path / "white.hdr";
    {
        std::ofstream f(path, std::ios::binary);
        f << "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 4\n";
        for (int i = 0; i < 8; ++i)
            f << char(128) << char(128) << char(128) << char(129);
    }
    const Image map = load_image(path);
    ASSERT_EQ(map.width, 4);
    ASSERT_EQ(map.height, 2);
    EXPECT_FLOAT_EQ(map.rgb[5], 1.0f);
    const ShLight l = equirect_light(map, 2, parse_rule("lebedev:50"));
    EXPECT_NEAR(l.coeffs[0].y, 2.0 * std::sqrt(M_PI), 1e-5);
    EXPECT_NEAR(l.coeffs[1].y, 0.0, 1e-5);
    // Not an image at all.
    const auto bad = dir.path / "bad.hdr";
    std::ofstream(bad) << "#?RADIANCE\nnonsense";
    EXPECT_THROW(load_image(bad), Error);
}

} // namespace
} // namespace skybake

namespace skybake {

// A light file's sun: a negative irradiance or a zero direction is refused
// (naming the light), a direction of any other length is stored unit.
TEST(PrtFile, LightFileSunMustBePhysical) {
    const auto light = [](const std::string& dir, const std::string& irr) {
        return fmt::format(R"({{"format":"skybake-sh-light","version":1,"order":0,"coefficients":[[1,1,1]],)"
                           R"("sun_direction":{},"sun_irradiance":{}}})",
                           dir, irr);
    };
    const ShLight ok = light_from_json(light("[0,3,4]", "[1,2,0]"), "ok.json");
    EXPECT_FLOAT_EQ(ok.sun_direction.y, 0.6f);
    EXPECT_FLOAT_EQ(ok.sun_direction.z, 0.8f);
    EXPECT_EQ(ok.sun_irradiance, glm::vec3(1, 2, 0));
    for (const auto& [dir, irr, words] :
         {std::tuple<std::string, std::string, std::string>{"[0,1,0]", "[1,-0.5,1]", "negative"},
          {"[0,0,0]", "[1,1,1]", "zero length"},
          {"[0,0,0]", "[0,0,0]", "zero length"},
          {"[1e-30,0,0]", "[1,1,1]", "zero length"}}) {
        try {
            light_from_json(light(dir, irr), "bad.json");
            ADD_FAILURE() << dir << " " << irr << " was accepted";
        } catch (const Error& e) {
            EXPECT_EQ(e.where(), "light");
            EXPECT_NE(e.message().find(words), std::string::npos) << e.message();
            EXPECT_NE(e.message().find("bad.json"), std::string::npos) << e.message();
        }
    }
}

} // namespace skybake
