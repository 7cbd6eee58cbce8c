// The CPU sky renderer's images against geometry: where the sun is in a
// panorama, what the fisheye's centre pixel sees, and where the planet's limb
// lies in a view from space.
#include <cmath>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "skybake/error.h"
#include "skybake/sky.h"

using namespace skybake;

namespace {
const SkyModel& earth() {
    static const SkyModel m(atmosphere_preset("earth"));
    return m;
}
double luminance(const Image& im, int x, int y) {
    const float* p = im.pixel(x, y);
    return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
}
} // namespace

TEST(SkyRender, PanoramaHasItsBrightestPixelAtTheSun) {
    // Panorama: azimuth 0..360° left to right, elevation +90° at the top, one
    // pixel a degree. The sun (0.27° in radius) at azimuth 90.5°, elevation
    // 29.5° sits on the centre of pixel (90, 60).
    SkyRenderSettings s;
    s.view = SkyView::Panorama;
    s.width = 360;
    s.height = 180;
    s.sun_azimuth_deg = 90.5;
    s.sun_elevation_deg = 29.5;
    const Image im = render_sky(earth(), s);
    int bx = 0, by = 0;
    for (int y = 0; y < im.height; ++y)
        for (int x = 0; x < im.width; ++x)
            if (luminance(im, x, y) > luminance(im, bx, by)) {
                bx = x;
                by = y;
            }
    EXPECT_EQ(bx, 90) << "brightest pixel at (" << bx << ", " << by << ")";
    EXPECT_EQ(by, 60) << "brightest pixel at (" << bx << ", " << by << ")";
    // The opposite azimuth, at the same elevation, is sky only.
    EXPECT_LT(luminance(im, 270, 60), 0.01 * luminance(im, bx, by));
}

TEST(SkyRender, FisheyeCentreIsTheZenithRadiance) {
    SkyRenderSettings s;
    s.view = SkyView::Fisheye;
    s.width = s.height = 65; // odd: the centre pixel looks straight up
    s.sun_elevation_deg = 35.0;
    s.sun_disc = false;
    const Image im = render_sky(earth(), s);
    const double mu_s = std::sin(35.0 * M_PI / 180.0);
    const glm::dvec3 expect = earth().radiance(SkySample{1.0f, float(mu_s), float(mu_s), 1.0f}, SkyMethod::Tables) *
                              earth().atmosphere().sun_irradiance;
    ASSERT_GT(expect.z, 0.0);
    const float* c = im.pixel(32, 32);
    for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(c[k], expect[k], 1e-4 * expect[k] + 1e-9) << k;
    EXPECT_GT(c[2], c[0]); // a blue zenith
    // Outside the fisheye circle: nothing.
    EXPECT_EQ(luminance(im, 0, 0), 0.0);
}

TEST(SkyRender, PlanetLimbFromSpaceIsWhereGeometryPutsIt) {
    // Looking straight down from 20,000 km with a 40° field of view: the
    // atmosphere's top subtends asin(R_top / r) from the nadir and the ground
    // asin(R0 / r). Outside the top's disc there is only black space (the sun
    // is behind the camera); inside the ground's disc, lit ground.
    const Atmosphere& a = earth().atmosphere();
    SkyRenderSettings s;
    s.view = SkyView::Camera;
    s.altitude_km = 20000.0;
    s.fov_deg = 40.0;
    s.pitch_deg = -90.0;
    s.width = s.height = 201;
    s.sun_elevation_deg = 60.0;
    const Image im = render_sky(earth(), s);
    const double r = a.planet_radius_km + s.altitude_km;
    const double top = std::asin(a.top_radius_km / r), ground = std::asin(a.planet_radius_km / r);
    const double tan_half = std::tan(20.0 * M_PI / 180.0), half = s.width / 2.0;
    const double pixel = std::atan(tan_half / half); // angular size of one pixel at the centre
    int space = 0, lit = 0;
    for (int y = 0; y < im.height; ++y)
        for (int x = 0; x < im.width; ++x) {
            const double dx = (x + 0.5 - half) / half * tan_half, dy = (y + 0.5 - half) / half * tan_half;
            const double angle = std::atan(std::sqrt(dx * dx + dy * dy)); // from the nadir
            if (angle > top + pixel) {
                ASSERT_EQ(luminance(im, x, y), 0.0) << "space at (" << x << ", " << y << ")";
                ++space;
            } else if (angle < ground - 2 * pixel) {
                ASSERT_GT(luminance(im, x, y), 0.0) << "ground at (" << x << ", " << y << ")";
                ++lit;
            }
        }
    EXPECT_GT(space, 1000);
    EXPECT_GT(lit, 10000);
}

TEST(SkyRender, CudaRendererRefusesTheExactMethod) {
    // skybake/sky.h: render_sky_cuda throws for SkyMethod::Exact, with or
    // without a device, and names the way out.
    SkyRenderSettings s;
    s.width = s.height = 8;
    s.method = SkyMethod::Exact;
    try {
        render_sky_cuda(earth(), s);
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("exact method runs on the CPU only"), std::string::npos) << e.what();
    }
}
