// Flags of the OpenGL planet renderer, shared by `sky render --renderer gl`,
// `fly` and `view planet`.
#pragma once

#include <string>

#include "flags.h"
#include "skybake/render.h"

namespace skybake::cli {

struct GlRenderFlags {
    std::string shading = "vertex";
    double max_error_px = 1.0;
    std::size_t max_triangles = 2'000'000;
    double relief_km = 0.0;

    // with_relief: the planet commands; `sky render` compares with the CPU's smooth sphere.
    void add(CLI::App& sub, bool with_relief) {
        sub.add_option("--shading", shading,
                       "OpenGL: where the sky function runs, vertex (the seed: sky shell and planet mesh vertices) or "
                       "pixel")
            ->capture_default_str();
        sub.add_option("--max-error-px", max_error_px, "OpenGL: screen-space error bound of the planet mesh, pixels")
            ->check(real_in(0.01, 1000.0, "pixels"))
            ->capture_default_str();
        sub.add_option("--max-triangles", max_triangles, "OpenGL: triangle budget of the planet mesh")
            ->check(integer_in(20, 50'000'000))
            ->capture_default_str();
        if (with_relief)
            sub.add_option("--relief", relief_km,
                           "Deterministic procedural terrain up to this height, km (0: the smooth sphere)")
                ->check(real_in(0.0, 20.0, "km"))
                ->capture_default_str();
    }
    // Refuses the flags of the OpenGL renderer for another renderer.
    void refuse(const CLI::App& sub, const std::string& reason) const {
        for (const char* f : {"--shading", "--max-error-px", "--max-triangles"})
            refuse_if_given(sub, f, reason);
    }
    PlanetRenderOptions options(PlanetSky source) const {
        PlanetRenderOptions o;
        if (shading == "vertex")
            o.shading = ShadingRate::Vertex;
        else if (shading == "pixel")
            o.shading = ShadingRate::Pixel;
        else
            throw UsageError("unknown shading '" + shading + "'; use vertex or pixel", "--shading");
        o.sky = source;
        o.max_error_px = max_error_px;
        o.max_triangles = max_triangles;
        o.relief.amplitude_km = relief_km;
        return o;
    }
};

} // namespace skybake::cli
