// libFuzzer target: the PRT sidecar (OUT.prt.json) checked against its mesh
// (prt_from_sidecar_json, what load_prt() does for `prt relight`). The mesh
// is fixed: one triangle carrying every attribute a sidecar may list
// (prt_0 ... prt_60: order 8, three channels), an albedo and a shading
// coefficient. Whatever loads must be a transfer of the mesh's size with
// finite coefficients, whose sidecar written back loads the same.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "skybake/error.h"
#include "skybake/prt.h"

namespace {

skybake::Mesh fixed_mesh() {
    skybake::Mesh m;
    m.positions = {{0.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}};
    m.indices = {0, 1, 2};
    const int attributes = (3 * skybake::sh_count(skybake::kPrtMaxOrder) + 3) / 4;
    for (int a = 0; a < attributes; ++a) {
        std::vector<float> v(12);
        for (std::size_t i = 0; i < v.size(); ++i)
            v[i] = std::sin(float(a * 12 + int(i)));
        m.set_attribute(fmt::format("prt_{}", a), 4, std::move(v));
    }
    m.set_attribute("albedo", 3, std::vector<float>(9, 0.5f));
    m.set_attribute("shading", 1, {0.25f, 0.5f, 1.0f});
    return m;
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size > (1 << 20))
        return 0;
    static const skybake::Mesh mesh = fixed_mesh();
    try {
        const skybake::PrtModel m = skybake::prt_from_sidecar_json(
            std::string_view(reinterpret_cast<const char*>(data), size), mesh, "fuzz.prt.json", "fuzz.glb");
        const skybake::Transfer& t = m.transfer;
        skybake::validate_mesh(m.mesh);
        if (t.order < 0 || t.order > skybake::kPrtMaxOrder || t.coefficients != skybake::sh_count(t.order) ||
            (t.channels != 1 && t.channels != 3) || t.vertices() != mesh.vertex_count() ||
            t.coeffs.size() != mesh.vertex_count() * std::size_t(t.channels * t.coefficients) ||
            m.albedo.size() != mesh.vertex_count())
            std::abort();
        for (float x : t.coeffs)
            if (!std::isfinite(x))
                std::abort();
        const std::string again = skybake::transfer_sidecar_json(t, mesh.vertex_count(), "vertex-colors");
        const skybake::PrtModel back = skybake::prt_from_sidecar_json(again, mesh, "round trip", "fuzz.glb");
        const skybake::Transfer& b = back.transfer;
        if (b.order != t.order || b.channels != t.channels || b.kind != t.kind || b.model != t.model ||
            b.bounces != t.bounces || b.rule != t.rule || b.coeffs != t.coeffs)
            std::abort(); // the writer and the reader disagree
    } catch (const skybake::Error&) {
    }
    return 0;
}
