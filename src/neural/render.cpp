// Sky images with the neural sky: Pietras & Rudnicki (seed 000), section III
// for the sky and the light scattered in front of the ground (one network
// evaluation per view ray, at the point where the ray enters the atmosphere),
// section IV for the ground: the in-scattered light in front of it is the
// difference of two network evaluations (observer and a probe at the surface
// point), the reflected light and the sun disc come from the optical-length
// tables. The camera, the planet and the ground are those
// of the sky module's renderer (src/sky/render_hd.h).
#include <algorithm>
#include <cmath>

#include "core/parallel.h"
#include "core/progress.h"
#include "neural/internal.h"
#include "neural/render_hd.h"
#include "sky/device.h"
#include "skybake/error.h"

namespace skybake {

using namespace neural;

Image render_neural_sky(const NeuralSky& net, const SkyModel& model, const SkyRenderSettings& s) {
    net.validate("neural sky");
    const sky::RenderHD p = sky::make_render_hd(model, s);
    const MlpHD hd = make_mlp_hd(net);

    return sky::render_pixels(p, [&](const glm::vec3& d) { return shade_ray_neural(p, hd, d); });
}

std::vector<PublishedView> published_views(int width, int height) {
    auto view = [&](const char* name, double alt, double sun_el, double sun_az, double pitch, double yaw) {
        PublishedView v;
        v.name = name;
        v.settings.altitude_km = alt;
        v.settings.sun_elevation_deg = sun_el;
        v.settings.sun_azimuth_deg = sun_az;
        v.settings.view = SkyView::Camera;
        v.settings.fov_deg = 90.0;
        v.settings.pitch_deg = pitch;
        v.settings.yaw_deg = yaw;
        v.settings.width = width;
        v.settings.height = height;
        return v;
    };
    return {view("1_sea_level", 0.0, 35.0, 40.0, 15.0, 0.0),   view("2_higher", 5.0, 35.0, 40.0, 5.0, 0.0),
            view("3_higher", 30.0, 35.0, 40.0, -10.0, 0.0),    view("4_higher", 120.0, 35.0, 40.0, -25.0, 0.0),
            view("5_low_sun", 0.0, 2.0, 0.0, 10.0, 0.0),       view("6_very_high", 1500.0, 35.0, 40.0, -70.0, 0.0)};
}

double image_psnr_db(const Image& a, const Image& b, const ToneMap& tm) {
    if (a.width != b.width || a.height != b.height || a.rgb.size() != b.rgb.size())
        throw Error("images of different sizes", "PSNR");
    double se = 0.0;
    for (std::size_t i = 0; i < a.rgb.size(); ++i) {
        const double x = linear_to_srgb(tone_map_value(a.rgb[i], tm));
        const double y = linear_to_srgb(tone_map_value(b.rgb[i], tm));
        // A NaN or infinite value is the largest error (tone mapping would hide it).
        se += std::isfinite(a.rgb[i]) && std::isfinite(b.rgb[i]) ? (x - y) * (x - y) : 1.0;
    }
    const double mse = se / double(std::max<std::size_t>(1, a.rgb.size()));
    return mse > 0.0 ? 10.0 * std::log10(1.0 / mse) : 999.0;
}

} // namespace skybake
