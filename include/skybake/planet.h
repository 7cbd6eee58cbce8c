// skybake/planet.h: a view-dependent, crack-free planet mesh (continuous level
// of detail on the icosahedron), pure C++, no graphics API.
//
// [SECTION] Units and frames
// [SECTION] Camera
// [SECTION] Relief
// [SECTION] Options and statistics
// [SECTION] The mesh
//
// Scheme: longest-edge bisection of triangle pairs ("diamonds") with split and
// merge operations kept from frame to frame, after Duchaineau et al. 1997
// (ROAM) on the triangle bintree, and Lindstrom & Pascucci 2002 for the
// diamond view of the hierarchy. The 20 faces of the icosahedron are paired
// into 10 rhombi, the root diamonds. See docs/planet.md.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <glm/vec3.hpp>

namespace skybake {

// [SECTION] Units and frames ---------------------------------------------------
//
// Positions are in kilometres, in a planet-centred frame, in double precision.
// What goes to the GPU is relative to the camera (position − camera, in double,
// then rounded to float): 1 m above a 6371 km planet the nearest vertices are
// metres away and keep about 0.1 µm of float resolution.

// [SECTION] Camera ---------------------------------------------------------------
struct PlanetCamera {
    glm::dvec3 position_km{0.0, 0.0, 6371.001}; // planet-centred, km
    glm::dvec3 forward{1.0, 0.0, 0.0};          // unit view direction
    glm::dvec3 up{0.0, 0.0, 1.0};               // unit, orthogonal to forward
    double fov_y_rad = 1.0;                     // vertical field of view, in (0, π)
    int viewport_width = 1280;                  // pixels, ≥ 1
    int viewport_height = 1024;                 // pixels, ≥ 1
    // Viewport height / (2 tan(fov_y / 2)): pixels per unit of (size / distance).
    double pixels_per_radian() const;
};

// [SECTION] Relief -----------------------------------------------------------------
//
// Optional deterministic procedural terrain: fractal value noise (octaves of
// halving wavelength and amplitude) on the unit sphere, heights in
// [0, amplitude_km] above the planet radius. amplitude_km = 0 is the smooth
// sphere (the default).
struct PlanetRelief {
    double amplitude_km = 0.0;          // highest possible terrain, ≥ 0
    double base_wavelength_km = 2000.0; // wavelength of the first octave, > 0
    int octaves = 16;                   // 1 to 30
    std::uint64_t seed = 1;
};

// Terrain height (km, in [0, amplitude_km]) at a unit direction from the planet centre.
double relief_height_km(const PlanetRelief& relief, const glm::dvec3& unit_direction);

// [SECTION] Options and statistics -----------------------------------------------------
struct ClodOptions {
    double planet_radius_km = 6371.0; // > 0
    PlanetRelief relief;
    double max_error_px = 1.0;             // screen-space error bound, pixels, > 0
    std::size_t max_triangles = 2'000'000; // triangle budget, ≥ 20
    bool cull = true;                      // triangles outside the view frustum or beyond the horizon get error 0
    int max_level = 60;                    // deepest bisection level (level 0: the icosahedron's 20 faces)
};

struct ClodStats {
    std::size_t triangles = 0;   // leaves after the update
    std::size_t vertices = 0;    // live vertices
    std::size_t splits = 0;      // diamonds split in this update (forced splits included)
    std::size_t merges = 0;      // diamonds merged in this update
    double max_error_px = 0.0;   // largest screen-space error of a leaf after the update
    bool budget_reached = false; // a split was refused because of max_triangles
    int max_level = 0;           // deepest leaf
};

// [SECTION] The mesh ----------------------------------------------------------------------
//
// The mesh starts as the icosahedron and is refined by update(camera): leaves
// whose screen-space error exceeds max_error_px are split (with the forced
// splits that keep the mesh conforming, i.e. crack-free), and diamonds whose
// merged error is within the bound are merged; splits stop at the triangle
// budget. Everything is deterministic: the same sequence of cameras gives the
// same mesh, the same vertex ids and the same index order.
//
// Screen-space error of a triangle: its object-space error (the largest
// distance between the flat triangle and the surface it stands for, km) over
// a lower bound of its distance to the camera, times pixels_per_radian().
// On the smooth sphere the object-space error is exact: R minus the distance
// from the centre to the triangle's plane. With relief it adds an estimate of
// the terrain the triangle cannot resolve.
class PlanetMesh {
public:
    explicit PlanetMesh(const ClodOptions& options = {}); // asserts valid options
    ~PlanetMesh();
    PlanetMesh(PlanetMesh&&) noexcept;
    PlanetMesh& operator=(PlanetMesh&&) noexcept;

    ClodStats update(const PlanetCamera& camera);
    const ClodOptions& options() const;

    std::size_t triangle_count() const;
    // Capacity of the vertex arrays: vertex ids are below this (some may be free).
    std::size_t vertex_capacity() const;

    // Leaf triangles, counter-clockwise seen from outside, 3 vertex ids each;
    // `indices` is resized to 3 * triangle_count().
    void indices(std::vector<std::uint32_t>& indices) const;
    // Vertex positions relative to `origin_km` as float, 3 floats per vertex id
    // (vertex_capacity() vertices; free ids hold 0), and unit surface normals
    // (radial on the smooth sphere), 3 floats per vertex id.
    void vertices(const glm::dvec3& origin_km, std::vector<float>& positions, std::vector<float>& normals) const;
    // Planet-centred position of a vertex id, km, double.
    glm::dvec3 vertex_position_km(std::uint32_t vertex) const;
    // Per leaf (in the order of indices()): object-space error in km and the
    // screen-space error in pixels that the last update() assigned (0 when culled).
    void leaf_errors(std::vector<double>& object_km, std::vector<double>& screen_px) const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

} // namespace skybake
