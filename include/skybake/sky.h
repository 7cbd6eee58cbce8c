// skybake/sky.h: single-scattering sky model (Nishita et al. 1993) with the
// optical-length tables and the marching sum of Pietras & Rudnicki (seed 000),
// an exact double-precision reference, and multiple scattering (Bruneton 2017's
// precomputed orders or Hillaire 2020's look-up table) added on request.
//
// [SECTION] Units and frames
// [SECTION] Atmosphere description
// [SECTION] Multiple scattering
// [SECTION] Presets and JSON files
// [SECTION] Phase functions and density profiles
// [SECTION] Input space of the sky function
// [SECTION] Optical-length tables
// [SECTION] Sky colour
// [SECTION] Surface colour
// [SECTION] Rendering
//
// See docs/sky.md for the maths, the measured errors and examples.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "skybake/image.h"

namespace skybake {

// [SECTION] Units and frames ---------------------------------------------------
//
// Lengths are in kilometres for every preset ("_km"); scattering and extinction
// coefficients are per kilometre ("_per_km"). Optical lengths t = ∫ρ ds are in
// kilometres (relative density times length). Colours are RGB triples; for the
// presets the channels are R, G, B in that order.
//
// Radiance is per unit sun irradiance at the top of the atmosphere, in 1/sr:
// multiply by the sun irradiance to get radiance in the irradiance's unit per sr.
//
// Angles of the sky function, all cosines (seed 000 notation):
//   cos α: view direction V against the local vertical U ("cos_view_zenith"),
//   cos β: view direction V against the sun direction L ("cos_view_sun"),
//   cos θ: local vertical U against the sun direction L ("cos_sun_zenith").
// V points from the observer into the sky, L points from the scene to the sun.

// [SECTION] Atmosphere description --------------------------------------------

enum class PhaseFunction : int {
    None = 0,              // absorbs only (e.g. ozone); scattering must be 0
    Rayleigh = 1,          // 3/(16π) (1 + cos²)
    HenyeyGreenstein = 2,  // (1 − g²) / (4π (1 + g² − 2g cos)^1.5)
    CornetteShanks = 3,    // 3(1 − g²)(1 + cos²) / (8π (2 + g²)(1 + g² − 2g cos)^1.5)
    // "pietras-rudnicki-mie": the Mie phase as printed by Pietras & Rudnicki
    // (the neural sky paper, seed 000): (1 − g²) / (16π (1 + g² − 2g cos)^1.5).
    // This is Henyey–Greenstein / 4 and integrates to 1/4, not 1. Files may
    // still spell it "seed-mie".
    PietrasRudnickiMie = 4,
};

enum class DensityProfile : int {
    Exponential = 0, // ρ = exp(−h / scale_height_km)
    Tent = 1,        // ρ = max(0, 1 − |h − tent_center_km| / tent_half_width_km) (ozone-like)
    Constant = 2,    // ρ = 1 everywhere below the top (a uniform shell; for tests)
};

struct AtmosphereComponent {
    std::string name;                      // "rayleigh", "mie", "ozone", ...
    DensityProfile profile = DensityProfile::Exponential;
    double scale_height_km = 8.0;          // Exponential only; > 0
    double tent_center_km = 25.0;          // Tent only: altitude of the peak
    double tent_half_width_km = 15.0;      // Tent only; > 0
    glm::dvec3 scattering_per_km{0.0};     // at relative density 1, per channel, ≥ 0
    glm::dvec3 extinction_per_km{0.0};     // at relative density 1, per channel, ≥ scattering
    PhaseFunction phase = PhaseFunction::Rayleigh;
    double phase_g = 0.0;                  // asymmetry parameter in (−1, 1) for HG, CS and PietrasRudnickiMie
};

// How each shell of the optical-length table weighs its length (see docs/sky.md).
enum class TableRule : int {
    AsPublished = 0, // "as-published" (files may say "seed"): Pietras & Rudnicki's rule as printed,
                     // S = ρ_i s_i, the density at the shell's outer boundary
    Refined = 1,     // each shell cut into sub-shells at most H/16 thick, each weighted by its
                     // mean density (exact for vertical rays); same rows, same recursion
};

// "as-published" or "refined"; parse_table_rule() also takes the older
// "seed" for AsPublished, and throws skybake::Error naming `where` otherwise.
const char* table_rule_name(TableRule rule);
TableRule parse_table_rule(const std::string& text, const std::string& where = "table_rule");

// Which light the sky function counts (see [SECTION] Multiple scattering).
enum class Scattering : int {
    Single = 0,   // "single": light scattered once, as in seed 000 (the default of every preset)
    Multiple = 1, // "multiple": every order, with ground bounces at ground_albedo
};
enum class MultipleScatteringMethod : int {
    // "orders": Bruneton 2017's precomputed scattering orders 2..scattering_orders
    // in double precision on a 4D grid over (r, μ, μs, ν), ground bounces included.
    Orders = 0,
    // "hillaire": Hillaire 2020's isotropic ψms(h, μs) table (orders to infinity,
    // as a geometric series), added along the view ray: the fast path.
    Hillaire = 1,
};
const char* scattering_name(Scattering scattering);
const char* multiple_scattering_method_name(MultipleScatteringMethod method);
// Parse "single"/"multiple" and "orders"/"hillaire"; throw skybake::Error naming `where` otherwise.
Scattering parse_scattering(const std::string& text, const std::string& where = "scattering");
MultipleScatteringMethod parse_multiple_scattering_method(const std::string& text,
                                                         const std::string& where = "multiple_method");

struct Atmosphere {
    std::string name;
    double planet_radius_km = 6360.0; // R0, the ground
    double top_radius_km = 6420.0;    // the top of the atmosphere; > planet_radius_km
    // Any number (1 to 4) of components. The first must be Exponential: its
    // relative density ρ0 is the observer coordinate of the sky function.
    std::vector<AtmosphereComponent> components;
    // Sun: direction for rendering, irradiance at the top of the atmosphere
    // (radiances are per unit irradiance; the renderer multiplies by this).
    double sun_elevation_deg = 30.0; // above the observer's horizon
    double sun_azimuth_deg = 0.0;    // clockwise from the observer's +x ("north")
    glm::dvec3 sun_irradiance{1.0};
    double sun_angular_radius_rad = 0.004675;
    glm::dvec3 ground_albedo{0.1};   // Lambertian ground reflectance C, per channel, in [0, 1]
    TableRule table_rule = TableRule::AsPublished;
    // Multiple scattering (JSON "scattering", "multiple_method", "scattering_orders";
    // written only when not single, so single-scattering files are unchanged).
    Scattering scattering = Scattering::Single;
    MultipleScatteringMethod multiple_method = MultipleScatteringMethod::Orders;
    int scattering_orders = 4; // Orders only: the highest order counted, 2 to 32 (Bruneton's default is 4)

    // Throws skybake::Error naming the first bad field.
    void validate() const;
    // Altitude (km above the ground) where the first component has relative density rho in (0, 1].
    double altitude_from_density(double rho) const;
    // Relative density of the first component at altitude_km.
    double density_from_altitude(double altitude_km) const;
};

// [SECTION] Presets and JSON files ----------------------------------------------
//
// "earth"       physical Earth (Bruneton 2017 / Hillaire 2020 values, km units),
//               Rayleigh + Mie (Cornette–Shanks, g = 0.8) + ozone (tent 10–40 km).
// "paper"       seed 000 section VII with r = m = 10000 (override with r, m).
// "paper-dense" seed 000 section VII with r = m = 100.
// The seed gives no planet radius: the paper presets use R0 = 6371 km (Earth's
// mean radius), since its scale heights 8.3 and 1.6 are Earth's, in km; the top
// is at 100 km, where the gas density is 6e-6. Mie g = 0.76 (the seed gives none).
std::vector<std::string> atmosphere_preset_names();
// Throws skybake::Error for an unknown name. r and m apply to "paper" only
// (the seed's divisors of the Rayleigh and Mie coefficients; > 0).
Atmosphere atmosphere_preset(std::string_view name, double paper_r = 10000.0, double paper_m = 10000.0);

// JSON text <-> Atmosphere. Parsing throws skybake::Error naming `where` and the field.
std::string atmosphere_to_json(const Atmosphere& atmosphere);
Atmosphere atmosphere_from_json(std::string_view text, const std::string& where = "atmosphere JSON");
Atmosphere load_atmosphere(const std::filesystem::path& path);
void save_atmosphere(const std::filesystem::path& path, const Atmosphere& atmosphere);

// [SECTION] Phase functions and density profiles ---------------------------------
// cos_theta: cosine of the angle between the view direction and the sun
// direction (1: looking at the sun). Result in 1/sr.
double phase_function(PhaseFunction phase, double g, double cos_theta);
// "none", "rayleigh", "henyey-greenstein", "cornette-shanks", "pietras-rudnicki-mie"
// (also "seed-mie"), as atmosphere files spell them; parsing throws skybake::Error naming `where`.
const char* phase_function_name(PhaseFunction phase);
PhaseFunction parse_phase_function(const std::string& text, const std::string& where = "phase");
// Relative density of one component at altitude_km above the ground (≥ 0).
double relative_density(const AtmosphereComponent& component, double altitude_km);

// [SECTION] Input space of the sky function --------------------------------------
//
// The sky function I(cos α0, cos β0, cos θ0, ρ0) is defined on
// [−1, 1]³ × (0, 1]. Three cosines describe three real unit vectors (V, L, U)
// only when their Gram determinant is non-negative:
//     1 + 2abc − a² − b² − c² ≥ 0.
struct SkySample {
    float cos_view_zenith = 1.0f; // cos α0 = V·U at the observer
    float cos_view_sun = 1.0f;    // cos β0 = V·L
    float cos_sun_zenith = 1.0f;  // cos θ0 = U·L at the observer
    float density = 1.0f;         // ρ0: relative density of the first component at the observer, in (0, 1]
};

// 1 + 2abc − a² − b² − c² (the Gram determinant of three unit vectors).
double cosine_triple_determinant(double a, double b, double c);
// Determinant ≥ −tolerance and each cosine in [−1, 1].
bool is_valid_cosine_triple(double a, double b, double c, double tolerance = 1e-6);
// Valid triple and density in (0, 1] (all finite).
bool is_valid_sky_sample(const SkySample& sample, double tolerance = 1e-6);
// Throws skybake::Error saying what is wrong, naming `where`.
void check_sky_sample(const SkySample& sample, const std::string& where);
// Samples from CSV text with the columns cos_view_zenith, cos_view_sun,
// cos_sun_zenith and density. The first line is either a header naming all
// four, in any order (other or repeated names are an error), or the first row
// of numbers, read in that order. Blank lines are skipped. Throws
// skybake::Error naming the line of `name` (a file name, for messages) for a
// row that is not four numbers or not a valid sample, and for no rows at all.
std::vector<SkySample> read_sky_samples_csv(std::string_view text, const std::string& name);
// `count` valid samples drawn uniformly from [−1,1]³ × (0,1] with rejection of
// invalid triples; deterministic in seed, independent of the thread count.
std::vector<SkySample> draw_sky_samples(std::size_t count, std::uint64_t seed);
// The samples of a flight from the ground to space: the observer's altitude
// uniform in [0, max_altitude_km] (density = Atmosphere::density_from_altitude),
// the sun's elevation uniform in [min_sun_elevation_deg, 90°], the view
// direction uniform on the sphere. Deterministic in seed. Throws
// skybake::Error ("FlightSampling") for a range that is empty.
struct FlightSampling {
    double max_altitude_km = 60.0;
    double min_sun_elevation_deg = -20.0;
};
std::vector<SkySample> draw_flight_samples(std::size_t count, std::uint64_t seed, const Atmosphere& atmosphere,
                                           const FlightSampling& sampling = {});

// [SECTION] Optical-length tables -------------------------------------------------
//
// Seed 000 section I. For each component k two tables over (u, c):
//   S[u, c]: one shell's contribution ρ_i s_i,
//   L[u, c]: the optical length from a point to the top, Σ S along the ray.
// u is the table's height coordinate: for Exponential components the relative
// density ρ, sampled uniformly ρ_i = i/n as in the seed; for Tent and Constant
// components the altitude over the atmosphere's height, uniformly. c = cos α is
// sampled uniformly on [0, 1]; downward rays use the seed's symmetry
// L[ρ, −c] = 2 L[ρ_x, 0] − L[ρ, c], with ρ_x the density at the tangent point.
struct TableResolution {
    int shells = 256;  // n: rows are u_i = i/n, i = 0..n; ≥ 2
    int cosines = 128; // m: columns are c_j = j/m, j = 0..m; ≥ 2
};

class OpticalLengthTables {
public:
    OpticalLengthTables() = default;
    // Builds the S and L tables of every component (in double, stored as float).
    static OpticalLengthTables build(const Atmosphere& atmosphere, const TableResolution& resolution = {});

    // Bilinear lookup of t = ∫ρ_k ds from altitude_km towards the direction with
    // cos_zenith (−1..1) to the top, in km. Downward rays that hit the ground use
    // the seed's clamp ρ_x = 1 (their differences along one ray stay exact).
    double optical_length(int component, double altitude_km, double cos_zenith) const;

    int components() const { return int(length_.size()); }
    int rows() const { return resolution_.shells + 1; }
    int columns() const { return resolution_.cosines + 1; }
    const TableResolution& resolution() const { return resolution_; }
    // Row-major, rows() x columns() floats: [row * columns() + column].
    const std::vector<float>& length_table(int component) const { return length_[std::size_t(component)]; }
    const std::vector<float>& shell_table(int component) const { return shell_[std::size_t(component)]; }
    const Atmosphere& atmosphere() const { return atmosphere_; }

private:
    Atmosphere atmosphere_;
    TableResolution resolution_;
    std::vector<std::vector<float>> length_, shell_;
};

// Exact optical length ∫ρ_k ds from altitude_km in the direction cos_zenith to
// the top of the atmosphere, by adaptive Gauss–Kronrod quadrature in double
// precision along the true ray. +infinity when the ray hits the ground.
double optical_length_exact(const Atmosphere& atmosphere, int component, double altitude_km, double cos_zenith);

// [SECTION] Sky colour -------------------------------------------------------------
enum class SkyMethod : int {
    Tables = 0, // the seed's marching sum over the optical-length tables (float)
    Exact = 1,  // adaptive quadrature along the true geometry (double)
};

// [SECTION] Multiple scattering ---------------------------------------------------
//
// With Atmosphere::scattering == Multiple, every radiance of SkyModel (both
// methods, the renderer, the CUDA path) adds the light scattered two or more
// times to the single-scattering sum: I = I1 + Ims. Ims comes from tables
// built once in the SkyModel constructor, in double precision:
//   orders:   Bruneton 2017. Transmittance T(r, μ); single scattering per
//             component without its phase; then for n = 2..N the scattering
//             density J_n (the order n − 1 radiance and the ground's order n − 1
//             irradiance, reflected at the albedo, integrated over the sphere with
//             each component's phase), the order-n radiance ∫ T J_n along every
//             ray, and the ground irradiance of order n. Ims = Σ_{n≥2} order n,
//             quadrilinear in the 4D grid.
//   hillaire: Hillaire 2020. For each altitude and sun cosine, the
//             second-order light L2 and the transfer f_ms of an isotropic
//             medium, ψms = L2 / (1 − f_ms); along the view ray Ims = ∫ T σs ψms.
// The sky irradiance of a horizontal surface (scattered light only) is
// tabulated from the model's own total radiance; the surface colour and the
// rendered ground add it to the direct sun. A brute-force path tracer
// (skybake/sky_path_tracer.h) is the reference for both methods.
//
// Building the tables takes seconds (orders: about 5 s for Earth on two
// cores; see docs/PERFORMANCE.md), with a progress bar on a terminal. They are
// cached on disk, in sky_table_cache_dir(), keyed by every input they depend
// on (the atmosphere without its name and sun, the options below, the steps
// and optical-length tables, the skybake version and the compiler), so the
// next model of the same atmosphere reads them back in milliseconds, bit for
// bit the tables it would compute. A missing, truncated or corrupt file is
// recomputed and rewritten without a word; files are renamed into place
// whole, so any number of processes may share the folder.
struct MultipleScatteringResolution {
    int r = 16;        // radius nodes of the orders grid, ≥ 2
    int mu = 32;       // view-cosine nodes per half (above / below the horizon), ≥ 2
    int mu_s = 32;     // sun-cosine nodes, ≥ 2
    int nu = 8;        // view–sun cosine nodes, ≥ 2
    // Polar samples of the sphere integrals, ≥ 4; azimuths: twice as many. The
    // orders: Gauss–Legendre in cos θ on each interval between the nadir, the
    // geometric horizon, the horizontal and the zenith (a third each; half on
    // each side of the horizon on the ground; an odd count loses one node);
    // Hillaire's table and the sky irradiance: midpoint bands. 24 resolves
    // the sky's light 8–16° after sunset, 16 did not (docs/sky.md, "At night").
    int sphere = 24;
    int psi_r = 32, psi_mu_s = 32;           // Hillaire's ψms table, ≥ 2 each
    int irradiance_r = 8, irradiance_mu_s = 64; // sky irradiance table, ≥ 2 each
    // Lowest sun cosine of the orders grid, in (−1, 0]: cos 120°, where the
    // night sky is 1e-12 of the day's (Bruneton's cos 102° froze the sky at
    // its twilight value below the sun's −11.5°).
    double mu_s_min = -0.5;
};

// The folder of the table cache: skybake::cache_dir() (skybake/files.h):
// $SKYBAKE_CACHE_DIR ("off" disables the cache), else $XDG_CACHE_HOME/skybake,
// else ~/.cache/skybake; empty when disabled. Read at each SkyModel construction.
std::filesystem::path sky_table_cache_dir();

struct SkyModelOptions {
    TableResolution tables{};
    // Steps of the seed's sum along the view ray (midpoint rule).
    // 16 meets 2,000,000 samples/s on two cores; see docs/PERFORMANCE.md.
    int steps = 16;
    // false: midpoints graded geometrically away from the ray's lowest point
    // (default; ~10x more accurate at 16 steps); true: the seed's uniform Δv.
    bool uniform_steps = false;
    // Relative tolerance of the exact quadrature.
    double exact_tolerance = 1e-7;
    // Tables of multiple scattering (used when the atmosphere asks for it).
    MultipleScatteringResolution multiple{};
};

// Single-scattered radiance I per unit sun irradiance, in 1/sr, looking from
// the observer along V until the ray leaves the atmosphere or meets the
// ground; samples in the planet's shadow add nothing. Observers above the top
// of the atmosphere (tiny ρ0) see the atmosphere from outside.
class SkyModel;
namespace sky {
struct AtmosphereHD; // the flat form the CPU/GPU code of src/sky/ reads
const AtmosphereHD& atmosphere_hd(const SkyModel& model);
} // namespace sky

class SkyModel {
public:
    explicit SkyModel(Atmosphere atmosphere, const SkyModelOptions& options = {});
    ~SkyModel();
    SkyModel(SkyModel&&) noexcept;
    SkyModel& operator=(SkyModel&&) noexcept;

    const Atmosphere& atmosphere() const;
    const OpticalLengthTables& tables() const;
    const SkyModelOptions& options() const;

    // One sample; the sample must be valid (asserted).
    glm::dvec3 radiance(const SkySample& sample, SkyMethod method) const;
    // Same, from an observer at radius_km from the planet centre (may be above the top).
    glm::dvec3 radiance_at_radius(double radius_km, double cos_view_zenith, double cos_view_sun,
                                  double cos_sun_zenith, SkyMethod method) const;
    // Seed's sum with an explicit step count and spacing (for convergence studies).
    // Single scattering only, whatever the atmosphere's scattering.
    glm::dvec3 radiance_tables(const SkySample& sample, int steps, bool uniform_steps = false) const;
    // The multiple-scattering part Ims of radiance() (zero for single scattering),
    // from an observer at radius_km (may be above the top).
    glm::dvec3 multiple_radiance_at_radius(double radius_km, double cos_view_zenith, double cos_view_sun,
                                           double cos_sun_zenith) const;
    // Irradiance of the scattered sky light on a horizontal surface at
    // altitude_km (≥ 0) with the sun at cos_sun_zenith, per unit sun irradiance
    // (the direct sun excluded). Zero for single scattering.
    glm::dvec3 sky_irradiance(double altitude_km, double cos_sun_zenith) const;
    // Wall-clock seconds the constructor spent on the multiple-scattering
    // tables (computing them, or reading them from the cache), and their bytes.
    double multiple_precompute_seconds() const;
    std::size_t multiple_table_bytes() const;
    // True when the multiple-scattering tables came from the cache (false for
    // single scattering and for tables computed by this constructor).
    bool multiple_tables_from_cache() const;

private:
    friend const sky::AtmosphereHD& sky::atmosphere_hd(const SkyModel& model);
    int spacing() const;
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// Batch evaluation over all cores. out.size() must equal samples.size(); every
// sample must be valid (check with is_valid_sky_sample first; asserted).
// Deterministic, independent of the thread count.
void evaluate_sky(const SkyModel& model, std::span<const SkySample> samples, std::span<glm::vec3> out,
                  SkyMethod method);
// Convenience: builds a SkyModel with default options first.
void evaluate_sky(const Atmosphere& atmosphere, std::span<const SkySample> samples, std::span<glm::vec3> out,
                  SkyMethod method);

// [SECTION] Surface colour ------------------------------------------------------------
//
// Seed 000 section IV. Positions are in km in a planet-centred frame; the sun
// direction is a unit vector in the same frame.
struct SurfaceLight {
    // Light scattered into the view between observer and surface point, 1/sr:
    glm::dvec3 inscatter_seed{0.0};  // the seed's difference I(observer) − I(probe at the surface), tables
    glm::dvec3 inscatter_exact{0.0}; // exact quadrature over the segment
    // Sunlight reflected by the Lambertian surface and attenuated to the observer, 1/sr
    // (with multiple scattering, plus the sky's light: albedo/π times SkyModel::sky_irradiance):
    glm::dvec3 reflected_tables{0.0};
    glm::dvec3 reflected_exact{0.0};
    glm::dvec3 transmittance_exact{1.0}; // observer <- surface point
};

// surface_km: a point on or above the ground; its normal is radial. albedo C per channel.
SurfaceLight surface_light(const SkyModel& model, const glm::dvec3& observer_km, const glm::dvec3& surface_km,
                           const glm::dvec3& sun_direction, const glm::dvec3& albedo);

// [SECTION] Rendering ---------------------------------------------------------------------
enum class SkyView : int {
    Fisheye = 0,  // upward hemisphere, equidistant; zenith at the centre, azimuth 0 up, 90° right
    Panorama = 1, // equirectangular: azimuth 0..360° left to right, elevation +90° (top) to −90°
    Camera = 2,   // pinhole: horizontal field of view fov_deg, looking along yaw_deg / pitch_deg
};

struct SkyRenderSettings {
    double altitude_km = 0.0;       // observer above the ground, ≥ 0 (may be far outside the atmosphere)
    double sun_elevation_deg = 30.0;
    double sun_azimuth_deg = 0.0;
    SkyView view = SkyView::Fisheye;
    double fov_deg = 90.0;          // Camera only, horizontal, in (0, 180)
    double yaw_deg = 0.0;           // Camera: azimuth of the view centre
    double pitch_deg = 0.0;         // Camera: elevation of the view centre
    int width = 512, height = 512;
    SkyMethod method = SkyMethod::Tables;
    bool sun_disc = true;           // add the attenuated sun disc
    // false: Lambertian ground, radiance C cos θ / π (physical). true:
    // Pietras & Rudnicki's printed surface term, that radiance times Σ_k b_k ρ_k at the
    // ground (per km): it keeps the seed's thin atmospheres (r = m = 10000)
    // about as bright as their ground, as in the seed's images.
    bool published_ground = false;
};

// Linear radiance per pixel (times the atmosphere's sun irradiance): the sky,
// the lit and unlit ground (Lambert, the atmosphere's ground albedo) and the
// planet seen from space. Uses all cores.
Image render_sky(const SkyModel& model, const SkyRenderSettings& settings);

// [SECTION] GPU ------------------------------------------------------------------------------
// The tables method on CUDA device 0, with the same SKYBAKE_HD code as the CPU
// path (results agree to float rounding). Both throw skybake::Error when the
// build has no CUDA or no device is present; render_sky_cuda also for
// SkyMethod::Exact, which runs on the CPU only.
void evaluate_sky_cuda(const SkyModel& model, std::span<const SkySample> samples, std::span<glm::vec3> out);
Image render_sky_cuda(const SkyModel& model, const SkyRenderSettings& settings);

} // namespace skybake
