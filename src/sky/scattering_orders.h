// Precomputed scattering orders (Bruneton 2017) on the 4D grid of
// multiple_hd.h, in double precision on the CPU.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "skybake/sky.h"
#include "sky/multiple_hd.h"

namespace skybake {
class Progress;
}

namespace skybake::sky {

// The node layout of the orders grid, and its (r, μ, μs, ν) at each node.
struct Grid4Shape {
    int nr = 2, nmu = 2, nmus = 2, nnu = 2; // nmu per half
    double R0 = 6360.0, Rt = 6420.0, mu_s_min = -0.5;
    // The sun axis' coordinate of the horizon (μs = 0, grid4_mus_coordinate),
    // for grid4_mus_cell_below_horizon; ScatteringOrders::compute sets it.
    double x_horizon = 0.0;
    std::size_t nodes() const { return std::size_t(nr) * 2u * std::size_t(nmu) * std::size_t(nmus) * std::size_t(nnu); }
    // The geometry of node `index` (grid4_index order). ν is clamped to the
    // values that μ and μs allow; ground: the ray meets the ground.
    void node(std::size_t index, double& r, double& mu, double& mu_s, double& nu, bool& ground) const;
    Grid4Coord<double> coordinates(double r, double mu, double mu_s, double nu) const {
        return grid4_coordinates(R0, Rt, mu_s_min, r, mu, mu_s, nu);
    }
};

// What the orders' grids are stored per unit of, at radius r along cosine μ:
// the air's scattering (summed over the channels) at the ray's lowest point,
// relative to the ground's; 1 for a ray that meets the ground. Looking up
// or along from high up, the light of the scattering orders falls with the
// air's density, an e-fold between radius nodes near the top (7 km apart
// there); per unit of it, the grids interpolate linearly without the 7–10%
// excess between nodes. The run-time twin: orders_scale in sky_shared.h.
double orders_scale(const Atmosphere& atmosphere, double r, double mu);

class ScatteringOrders {
public:
    // Orders 1..orders (orders ≥ 2). keep_orders: keep each order's grid for
    // order_radiance(); otherwise only their sum from order 2 on. progress (may be
    // null) advances by progress_units() in all.
    static ScatteringOrders compute(const Atmosphere& atmosphere, const MultipleScatteringResolution& resolution,
                                    int orders, bool keep_orders = false, Progress* progress = nullptr);
    // The steps compute() reports: each node once for order 1, twice for each higher order.
    static std::uint64_t progress_units(const MultipleScatteringResolution& resolution, int orders);

    const Grid4Shape& shape() const { return shape_; }
    int orders() const { return orders_; }
    // Σ_{n=2..orders} order n at every node, RGB floats in grid4_index order (MultipleHD::orders).
    const std::vector<float>& residual() const { return residual_; }
    // Radiance of order n (1 ≤ n ≤ orders; needs keep_orders) towards an observer at
    // radius r ≤ Rt looking along (μ, μs, ν), per unit sun irradiance, 1/sr; order 1 with its phases.
    glm::dvec3 order_radiance(int n, double r, double mu, double mu_s, double nu) const;
    // Irradiance on the ground of the light scattered n − 1 times (n ≥ 2; needs keep_orders).
    glm::dvec3 ground_irradiance(int n, double mu_s) const;

private:
    Grid4Shape shape_;
    int orders_ = 0;
    Atmosphere atmosphere_;
    std::vector<float> residual_;
    // keep_orders: order 1 per component without phase (nodes × components), then orders 2.. (nodes).
    std::vector<glm::dvec3> single_;
    std::vector<std::vector<glm::dvec3>> multiple_;
    std::vector<std::vector<glm::dvec3>> irradiance_; // ground irradiance per order over kIrradianceNodes μs
};

} // namespace skybake::sky
