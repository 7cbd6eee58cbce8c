// The sky's device view, shared with the network (neural/) and the renderers
// (render/): the flat structs of the SKYBAKE_HD maths (sky_hd.h, render_hd.h)
// built from the public types, the model's split table path, and the CPU
// pixel loop. The rest of the sky's glue stays in sky/internal.h.
#pragma once

#include <span>

#include "core/parallel.h"
#include "core/progress.h"
#include "skybake/image.h"
#include "skybake/sky.h"
#include "sky/render_hd.h"
#include "sky/sky_hd.h"

namespace skybake::sky {

// Flat view of an atmosphere and its tables for the SKYBAKE_HD functions.
// The result points into `tables`, which must outlive it.
AtmosphereHD make_atmosphere_hd(const Atmosphere& atmosphere, const OpticalLengthTables& tables);

// Observer state from a radius (km) and the three cosines.
ObserverHD make_observer(const Atmosphere& atmosphere, double radius_km, double cos_view_zenith, double cos_view_sun,
                         double cos_sun_zenith);

// Observer state from a sky sample (ρ0 -> altitude of the first component).
ObserverHD make_observer(const Atmosphere& atmosphere, const SkySample& sample);

// The model's single-scattering table path split by component without the
// phase functions (seed_sky_sum_split), over all cores:
// out[i * components + k] for sample i and component k.
// With `scale` not empty, sample i sees component `component`'s scattering
// and extinction times scale[i] (an aerosol family: the tables hold optical
// lengths, which its amount does not change).
void evaluate_sky_split(const SkyModel& model, std::span<const SkySample> samples, std::span<glm::vec3> out,
                        std::span<const float> scale = {}, int component = -1);

// Validates the settings (throws skybake::Error naming the flag) and sets up
// the per-pixel parameters shared by the CPU and CUDA renderers.
RenderHD make_render_hd(const SkyModel& model, const SkyRenderSettings& settings);
// What the scene takes from the model: steps and spacing, ground albedo,
// irradiance and sun disc (make_render_hd's, and the planet renderer's).
void set_scene_hd(RenderHD& p, const SkyModel& model, bool published_ground, bool sun_disc);

// The CPU pixel loop: shade(dir) -> linear RGB for every pixel with a view
// direction, rows in parallel, with a progress bar. Pixels without a
// direction (outside the fisheye disc) stay black.
template <class Shade>
Image render_pixels(const RenderHD& p, Shade shade) {
    Image image(p.width, p.height);
    Progress progress("render", std::uint64_t(p.height));
    parallel_for(std::size_t(p.height), 1, [&](std::size_t y0, std::size_t y1) {
        for (std::size_t y = y0; y < y1; ++y) {
            for (int x = 0; x < p.width; ++x) {
                glm::vec3 d;
                if (!pixel_direction(p, x, int(y), d))
                    continue;
                const glm::vec3 c = shade(d);
                float* px = image.pixel(x, int(y));
                px[0] = c.x;
                px[1] = c.y;
                px[2] = c.z;
            }
            progress.advance();
        }
    });
    progress.finish();
    return image;
}

} // namespace skybake::sky
