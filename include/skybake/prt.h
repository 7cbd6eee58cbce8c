// skybake/prt.h: precomputed radiance transfer (PRT) of a baked mesh, lit by
// a low-frequency light in spherical harmonics: the sky, a map, a constant.
//
// Sloan, Kautz & Snyder, Precomputed Radiance Transfer for Real-Time Rendering
// in Dynamic, Low-Frequency Lighting Environments, SIGGRAPH 2002; seed 002
// (Svistunov) for the visibility words and the simplified B ≈ A · B̃;
// Ramamoorthi & Hanrahan 2001 for the irradiance convolution.
//
// [SECTION] Definitions
// [SECTION] Transfer bake
// [SECTION] Light
// [SECTION] Relighting
// [SECTION] Glossy transfer (DPRT)
// [SECTION] Shader export
// [SECTION] Files
//
// See docs/prt.md for the maths, the files, the measured errors and the
// command line (`skybake prt bake`, `skybake prt relight`, `skybake sky sh`).
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "skybake/bake.h"
#include "skybake/gltf_asset.h"
#include "skybake/image.h"
#include "skybake/mesh.h"
#include "skybake/neural.h"
#include "skybake/sh.h"
#include "skybake/sky_source.h"
#include "skybake/sphere.h"
#include "skybake/visibility.h"

namespace skybake {

// [SECTION] Definitions -------------------------------------------------------------
//
// Light: distant radiance L(x) (x a unit direction, world space) as real SH
// (skybake/sh.h) per RGB channel, L(x) = Σ_lm L_lm Y_lm(x), with
// L_lm = ∫ L Y_lm dω.
//
// Diffuse transfer of vertex p with unit normal n, for the normalised measure
// dμ = dω/4π and the seed's cosine weight 4 (n·x)+:
//     T_lm = ∫ Y_lm(x) V_p(x) 4 (n·x)+ dμ = (1/π) ∫ Y_lm V (n·x)+ dω,
// so that the outgoing radiance of a Lambertian surface of albedo ρ is
//     B = ρ (1/π) ∫ L V (n·x)+ dω = ρ Σ_lm L_lm T_lm      (per channel).
// A sphere rule {x_k, w_k} replaces the integral: T_lm = Σ_k w_k 4 (n·x_k)+ V_k Y_lm(x_k).
// Kinds (TransferKind):
//   unshadowed      V ≡ 1 above the horizon. Analytically
//                   T_lm = (Â_l / π) Y_lm(n), Â_l the clamped-cosine factors
//                   (Ramamoorthi & Hanrahan 2001; clamped_cosine_zonal()).
//   shadowed        V from the visibility words of the bake (skybake/visibility.h).
//   interreflected  shadowed plus N bounces (Sloan 2002, section 5): an
//                   occluded direction x_k brings the light the surface it hits
//                   sends back, B_hit = ρ_hit Σ L_lm T_lm(hit), with T at the hit
//                   interpolated from its triangle's vertices:
//                       T^(b)_lm(p) = T^(0)_lm(p) + Σ_k w_k 4 (n·x_k)+ (1 − V_k) ρ_hit T^(b−1)_lm(hit).
//                   Every ray is answered by RayQueries::intersect(). Per RGB
//                   channel, because ρ_hit is coloured; albedo ρ_p is not
//                   included (B = ρ_p Σ L T as before).
// With constant light L (L_00 = 2√π L, the rest 0), B = ρ L · 2√π Y_00 T_00 =
// ρ L Σ_k w_k 4 (n·x_k)+ V_k = ρ L · AO: the shadowed transfer's first
// coefficient is the ambient occlusion of skybake/bake.h times 2√π.
//
// Model (TransferModel):
//   prt                  the transfer above;
//   shading-coefficient  the seed's simplified form B ≈ A · B̃ with B̃ the
//                        unshadowed irradiance: T_lm = A (Â_l / π) Y_lm(n),
//                        A the shading coefficient (skybake/bake.h).
//
// Frames: world space of the mesh. The sky's zenith is +y (the glTF up axis);
// sun azimuth 0 is towards +z, 90° towards +x.

enum class TransferKind : int { Unshadowed = 0, Shadowed = 1, Interreflected = 2 };
enum class TransferModel : int { Prt = 0, ShadingCoefficient = 1 };
// "unshadowed", "shadowed", "interreflected"; "prt", "shading-coefficient".
const char* transfer_kind_name(TransferKind kind);
const char* transfer_model_name(TransferModel model);
// Throw skybake::Error (where: "kind" / "model") listing the names.
TransferKind parse_transfer_kind(const std::string& text);
TransferModel parse_transfer_model(const std::string& text);

// Highest SH band a transfer bake takes (81 coefficients).
inline constexpr int kPrtMaxOrder = 8;

// [SECTION] Transfer bake ---------------------------------------------------------------

struct TransferOptions {
    int order = 3; // lmax, 0 ... kPrtMaxOrder: (order + 1)² coefficients
    TransferKind kind = TransferKind::Shadowed;
    TransferModel model = TransferModel::Prt;
    int bounces = 0; // interreflected only: ≥ 1 (and ≤ 16)
};

// Per-vertex transfer vectors. coeffs holds vertices × channels × coefficients
// floats: vertex v, channel c (0 for grey transfer, else R, G, B), coefficient
// i = sh_index(l, m) at (v · channels + c) · coefficients + i.
struct Transfer {
    int order = 3;
    int coefficients = 16; // sh_count(order)
    int channels = 1;      // 1 (unshadowed, shadowed), 3 (interreflected)
    TransferKind kind = TransferKind::Shadowed;
    TransferModel model = TransferModel::Prt;
    int bounces = 0;
    std::string rule; // canonical rule spec of the bake
    std::vector<float> coeffs;
    // The shading coefficient A of every vertex, from the same bits (seed 002;
    // skybake/bake.h): the glossy factor of B ≈ A · B̃ (DPRT). Empty when unknown.
    std::vector<float> shading;

    std::size_t vertices() const { return coeffs.size() / std::size_t(channels * coefficients); }
    const float* vertex(std::size_t v, int channel = 0) const {
        return coeffs.data() + (v * std::size_t(channels) + std::size_t(channel)) * std::size_t(coefficients);
    }
};

// The reduction of the visibility words into diffuse transfer (shadowed or, with
// kind Unshadowed, ignoring the words; see [SECTION] Definitions). Use it with
// bake_visibility() like ShadingReduction; `out` gets one vector per vertex
// (channels 1). Also keeps the shading coefficient A per vertex (for the
// shading-coefficient model) and, with keep_words, the words (for bounces).
class TransferReduction final : public VisibilityReduction {
public:
    TransferReduction(Transfer& out, bool keep_words = false);
    void begin(const VisibilityRule& rule, std::size_t vertices) override;
    std::uint64_t reduce(const VisibilityChunk& chunk) override;

    const std::vector<float>& shading() const { return shading_; }
    const std::vector<std::uint32_t>& words() const { return words_; }

private:
    Transfer& out_;
    bool keep_words_;
    VisibilityRule rule_;
    std::vector<float> table_; // Y_i(points[j]) at j · coefficients + i, when the rule does not rotate
    std::vector<float> shading_;
    std::vector<std::uint32_t> words_;
};

struct TransferReport {
    std::string backend, rule;
    std::size_t vertices = 0, triangles = 0, directions = 0;
    std::uint64_t rays = 0;        // visibility rays
    std::uint64_t bounce_rays = 0; // closest-hit rays: one per occluded direction, reused by every bounce
    double seconds = 0.0, trace_seconds = 0.0, bounce_seconds = 0.0;
    float ray_offset = 0.0f;
};

// Bakes the transfer of every vertex. rule: a sphere rule (not a Phong rule);
// albedo: one linear RGB reflectance in [0, 1] per vertex (mesh.vertex_count()
// entries), used by the bounces only (may be empty otherwise); queries: a
// backend that answers ray queries, required for interreflected transfer
// (nullptr otherwise). With `images` (base_color_images(): glTF's --albedo
// material), a bounce off a triangle whose material has an image takes the
// albedo at the hit itself (surface_base_color(): the image at the hit's UV),
// not the vertices' interpolated albedo. Computes normals when the mesh has
// none. Throws skybake::Error naming the field: "order", "bounces", "kind",
// "albedo", "backend" (bounces without ray queries), and those of
// bake_visibility().
TransferReport bake_transfer(Mesh& mesh, const SphereRule& rule, VisibilityTracer& tracer, const BakeOptions& bake,
                             const TransferOptions& options, std::span<const glm::vec3> albedo, RayQueries* queries,
                             Transfer& out, const std::vector<Image>& images = {});

// The mesh's albedo for PRT, per vertex, as glTF defines the base colour:
// the material's base colour factor × its base colour image (bilinear at the
// vertex's UV, repeating; skipped when the file does not load) × the vertex
// colour (RGB), clamped to [0, 1]. A vertex without a material: its colour, or
// `fallback` when the mesh has no colours. A vertex of several parts takes the
// material of the first triangle that uses it. With `images` false the base
// colour images are left out (a renderer that samples them per pixel
// multiplies them in itself).
std::vector<glm::vec3> mesh_albedo(const Mesh& mesh, const glm::vec3& fallback = glm::vec3(0.8f),
                                   bool images = true);

// The same with the base colour images already decoded (base_color_images();
// a missing or empty entry leaves that material's image out).
std::vector<glm::vec3> mesh_albedo(const Mesh& mesh, const std::vector<Image>& images,
                                   const glm::vec3& fallback = glm::vec3(0.8f));

// Each material's base colour image, decoded (linear RGB), in the order of
// Mesh::materials; an empty Image where a material has none or its file does
// not load.
std::vector<Image> base_color_images(const Mesh& mesh);

// glTF's base colour at a point of triangle `triangle`, (u, v) the weights
// of its second and third vertex: the material's factor × its image
// (`images`, as base_color_images() decodes them) bilinear at the point's UV
// × the interpolated vertex colour, clamped to [0, 1]. False, and `out` left
// alone, where the triangle's material has no decoded image or no UVs.
bool surface_base_color(const Mesh& mesh, const std::vector<Image>& images, std::uint32_t triangle, float u, float v,
                        glm::vec3& out);

// Each vertex's material (that of the first triangle using it), or -1.
std::vector<int> vertex_materials(const Mesh& mesh);

// [SECTION] Light ----------------------------------------------------------------------------

// RGB radiance in SH: coeffs[sh_index(l, m)] = L_lm, sh_count(order) entries.
// Radiance in the source's unit (the sky: per unit sun irradiance, 1/sr).
struct ShLight {
    int order = 3;
    std::vector<glm::vec3> coeffs;
    // The sun as a direct light (not in the SH): direction (unit, world
    // space, towards the sun) and irradiance on a surface facing it (the
    // transmitted sun; zero when there is no sun or it is below the ground).
    glm::vec3 sun_direction{0.0f, 1.0f, 0.0f};
    glm::vec3 sun_irradiance{0.0f};
};

// Constant radiance in every direction: L_00 = 2√π · radiance.
ShLight constant_light(const glm::vec3& radiance, int order);
// c_lm = 4π Σ_k w_k f(x_k) Y_lm(x_k) per channel, with a sphere rule (not a
// Phong rule). Exact for f band-limited to l_f when the rule's precision is
// ≥ l_f + order.
ShLight project_light(const std::function<glm::vec3(const glm::vec3&)>& radiance, int order, const SphereRule& rule);
// An equirectangular map (the sample_equirect() layout of skybake/sh.h), its
// +z pole turned to the world's +y zenith: world direction (x, y, z) reads
// the map at (x, −z, y), so the top row is the zenith. Throws skybake::Error (where: "light") on an
// empty map or one that is not 2:1 within a pixel, or with non-finite pixels.
ShLight equirect_light(const Image& map, int order, const SphereRule& rule);
// The light turned by `rotation` (g(x) = f(rotationᵀ x), Ivanic–Ruedenberg).
ShLight rotate_light(const ShLight& light, const glm::mat3& rotation);

// The rule every sky projection uses unless told otherwise (sky sh, prt
// relight --light sky, the viewer, Python's sky_light): split at the horizon,
// where the sky steps down to the dark air below it, so that the step is
// integrated exactly (a rule with points on the horizon, such as every
// Lebedev rule, reads them at the bright side: +10% in L00 with lebedev:2030
// for a sun at 30°). Within 0.22% (L2 per channel, orders 2 to 8) of a
// converged projection for suns from −10° to 90° (docs/prt.md); 2304 points.
inline constexpr const char* kSkyLightRule = "horizon:32x36";

struct SkyLightSettings {
    double sun_elevation_deg = 30.0; // above the horizon, degrees
    double sun_azimuth_deg = 0.0;    // 0: towards +z, 90: towards +x
    double altitude_km = 0.0;        // observer above the ground, ≥ 0
    bool sun = true;                 // fill ShLight::sun_* (the transmitted sun)
    // The lit ground (off by default: below the horizon only the air's light).
    // With an albedo ρ (per channel, in [0, 1]), each direction that meets
    // the ground also gets the light of a Lambertian ground there,
    //     T(observer ← ground) · ρ/π · (max(s·u_g, 0) T_sun(ground) + E_sky),
    // u_g the ground point's vertical, T from the optical-length tables and
    // E_sky the sky's irradiance on a horizontal surface as the projection
    // sees it from the observer (exact at the ground; an approximation above
    // it), all per unit sun irradiance as the sky's radiance is. A model
    // standing on the ground then gets its bounce light.
    std::optional<glm::vec3> ground_albedo;
};

// World direction (unit, +y up) of a sun at this elevation and azimuth.
glm::vec3 sun_direction(double elevation_deg, double azimuth_deg);

// The sky seen from altitude_km, with the sun at (elevation, azimuth): its
// radiance per unit sun irradiance (SkySource::evaluate), above and below the
// horizon (below: the light scattered between the observer and the ground;
// the ground itself is not included), projected with `rule`. The sun is a
// direct light: sun_irradiance = the atmosphere's sun irradiance times the
// transmittance exp(−Σ_k β_k t_k) along the sun ray, t_k from the
// optical-length tables (zero once the sun is below the ground). Throws
// skybake::Error (where: "altitude_km", "sun_elevation_deg", "order").
ShLight sky_light(const SkySource& sky, const SkyLightSettings& settings, int order, const SphereRule& rule);

// Reusable sky projection for per-frame updates: the rule's SH table and
// samples are built once; project() then evaluates the sky and sums.
class SkyProjector {
public:
    SkyProjector(int order, const SphereRule& rule);
    ShLight project(const SkySource& sky, const SkyLightSettings& settings) const;
    int order() const { return order_; }

private:
    void add_lit_ground(const SkySource& sky, const SkyLightSettings& s, const glm::vec3& sun,
                        std::vector<glm::vec3>& radiance) const;
    int order_;
    std::vector<glm::vec3> points_;
    std::vector<float> weighted_table_; // 4π w_k Y_i(x_k) at k · coefficients + i
};

// Sun transmittance (per channel) from altitude_km towards a sun with
// cos_sun_zenith, from the optical-length tables; 0 when the ray meets the ground.
glm::dvec3 sun_transmittance(const SkyModel& tables, double altitude_km, double cos_sun_zenith);

// The sky as an image-based light for other engines (EXT_lights_image_based,
// which Babylon.js reads; gltf_asset.h writes it):
//   - irradiance: c_k = Â_l L_k, Â_l = π, 2π/3, π/4 (Ramamoorthi & Hanrahan
//     2001), L_k the order-2 SH of the sky of sky_light() (horizon handled by
//     `rule`) in Babylon.js's basis: Condon–Shortley signs, z the polar axis
//     (Y_1-1 = −√(3/4π) y, Y_10 = √(3/4π) z, Y_11 = −√(3/4π) x, Y_2-2 = √(15/4π)
//     xy, Y_2-1 = −√(15/4π) yz, Y_20 = √(5/16π) (3z² − 1), Y_21 = −√(15/4π) xz,
//     Y_22 = √(15/16π) (x² − y²)), over directions of the glTF frame (+y up).
//     Babylon.js's shading then gives ρ/π E(n), as relight() does unshadowed;
//   - faces: the sky's radiance (per unit sun irradiance, without the sun's
//     disc, which is the direct light) at each texel centre of an OpenGL cube
//     map in the glTF frame (face +X: direction (1, −t, −s), −X: (−1, −t, s),
//     +Y: (s, 1, t), −Y: (s, −1, −t), +Z: (s, −t, 1), −Z: (−s, −t, −1), with
//     s, t in (−1, 1) from the left column and the top row), one mip of
//     face_size², RGBD-encoded as Babylon.js decodes it (rgb = (c D)^(1/2.2),
//     alpha D, D = ⌊max(255 / max(c), 1)⌋ / 255, clamped to 1).
// Throws skybake::Error as sky_light(), and ("face_size") for a face size
// that is not a power of two from 1 to 1024.
ImageBasedLight sky_image_based_light(const SkySource& sky, const SkyLightSettings& settings, const SphereRule& rule,
                                      int face_size = 32);
// Babylon.js's order-2 basis above at unit direction d, in its order.
std::array<double, 9> babylon_sh_basis(const glm::dvec3& d);
// The unit direction of texel (column i, row j) of cube face `face` (0..5:
// +X, −X, +Y, −Y, +Z, −Z) of size n, as above.
glm::dvec3 cube_face_direction(int face, int i, int j, int n);

// [SECTION] Relighting -----------------------------------------------------------------------

// Outgoing radiance of every vertex, B_v = ρ_v Σ_lm L_lm T_lm(v) (per channel;
// the grey transfer is shared by the three channels), plus the sun:
// ρ_v (1/π) (n·s)+ E_sun sun_visible[v]. The light must have at least the
// transfer's order (higher bands are ignored). albedo: vertex_count entries;
// normals and sun_visible: empty to leave out the sun, else vertex_count
// entries (sun_visible: 1 lit, 0 shadowed). Throws skybake::Error (where:
// "light", "albedo").
std::vector<glm::vec3> relight(const Transfer& transfer, const ShLight& light, std::span<const glm::vec3> albedo,
                               std::span<const glm::vec3> normals = {}, std::span<const float> sun_visible = {});

// Per-vertex visibility of the sun (1 or 0) by one occlusion ray per vertex
// from the bake's ray origin.
std::vector<float> sun_visibility(const Mesh& mesh, const glm::vec3& sun_direction, RayQueries& queries);

// [SECTION] Glossy transfer (DPRT) ------------------------------------------------------------
//
// Svistunov's DPRT (seed 002): for the normalised Phong lobe of exponent a,
// ρ_a(r·x) = 2(a + 1) max(r·x, 0)^a around the mirror direction r = 2(n·v)n − v
// of the view v (unit, from the surface towards the eye) about the unit normal n,
//     B̃(v) = ∫ L(x) ρ_a(r·x) dμ ≈ Σ_k λ_k L(g_nv x_k),
// with {x_k, λ_k} a Phong rule (phong_rule(), lobe axis +z) and g_nv a rotation
// taking +z to r. The glossy radiance is then B(v) ≈ A · B̃(v) (A: the shading
// coefficient). Exact for L a polynomial of degree ≤ 2N − 1 (N: the rule's
// nodes in cos θ); the lobe's own degree does not enter, the rule's weights
// carry it. For an SH light the exact value is also Σ_lm k_l L_lm Y_lm(r) with
// k_l = 2(a+1)/(4π) · phong_lobe_zonal(l, a) (Funk–Hecke).

// A rotation (columns: tangent, bitangent, axis) taking +z to the unit `axis`.
glm::mat3 frame_from_axis(const glm::vec3& axis);
// The mirror direction 2(n·v)n − v.
glm::vec3 mirror_direction(const glm::vec3& normal, const glm::vec3& view);

// Σ_k λ_k L(g_nv x_k) for any light L (the SH light, or the sky evaluated
// directly). phong: a Phong rule; normal, view: unit, world space.
glm::vec3 dprt_glossy(const SphereRule& phong, const std::function<glm::vec3(const glm::vec3&)>& radiance,
                      const glm::vec3& normal, const glm::vec3& view);
// Same for an SH light (evaluated at each turned direction).
glm::vec3 dprt_glossy(const SphereRule& phong, const ShLight& light, const glm::vec3& normal, const glm::vec3& view);
// The exact Phong integral of an SH light by Funk–Hecke (the reference).
glm::vec3 phong_glossy_exact(const ShLight& light, double exponent_a, const glm::vec3& normal, const glm::vec3& view);

// An image of a relit model through the ray-cast preview of skybake/bake.h
// (render_ao_preview()'s camera): each hit gets the per-vertex `diffuse`
// radiance (mesh.vertex_count() entries, e.g. from relight()) interpolated,
// plus, when phong_exponent > 0, the DPRT glossy term
//     specular · A · Σ_k λ_k L(g_nv x_k)
// per pixel, with the normal and the shading coefficient A interpolated
// (A = 1 when the transfer has none), v towards the eye, and the Phong rule
// phong:a=exponent,n=order/2+1 (exact for the light's degree). A miss shows
// the SH light along the ray (clamped at 0). Linear radiance.
Image render_prt_preview(const Mesh& mesh, const Transfer& transfer, std::span<const glm::vec3> diffuse,
                         const ShLight& light, double phong_exponent, float specular,
                         const AoPreviewOptions& options = {});

// [SECTION] Shader export --------------------------------------------------------------------
//
// GLSL for engines (any GLSL ≥ 3.30 or ES 3.00, vertex or fragment shader):
//   vec3 NAME_diffuse(vec4 prt[M], vec3 light[C], vec3 albedo)
//       B = albedo Σ_i light[i] t_i for a grey transfer (channels 1), or per
//       channel for RGB transfer; prt[] the attributes _PRT_0 ... _PRT_{M-1}
//       in order, light[] the SH light (the "coefficients" of a light file).
//   vec3 NAME_glossy(vec3 n, vec3 v, vec3 sun, float density)   (with a network)
//       DPRT with the sky network evaluated directly: Σ_k λ_k sky(g_nv x_k),
//       the Phong rule's points and weights unrolled as constants; n, v, sun
//       unit, world space (+y up); density as SkySample::density. Multiply by
//       the shading coefficient (attribute _SHADING) and the sun irradiance.
//       The network's own function (export_neural_sky(), named NAME_sky) is
//       included.
struct PrtShaderOptions {
    std::string function_name = "skybake_prt";
    // The convention of the light[] that NAME_diffuse is given (the transfer
    // is stored in skybake's): with CondonShortley the function flips the
    // odd-|m| terms itself, so a light projected by D3DX-style code is used as
    // it is.
    ShConvention light_convention = ShConvention::Skybake;
    const SphereRule* phong = nullptr; // a Phong rule: adds NAME_glossy (needs network)
    const NeuralSky* network = nullptr;
    // GLSL ES 3.00 (WebGL 2) instead of GLSL 3.30: the functions compute in
    // highp whatever the shader's default precision is.
    bool es = false;
};
std::string export_prt_glsl(int order, int channels, const PrtShaderOptions& options = {});

// [SECTION] Files ------------------------------------------------------------------------------
//
// A baked mesh carries its transfer as attributes "prt_0", "prt_1", ... of 4
// components (glTF "_PRT_0", ...; PLY prt_0_x ... prt_0_w): the
// channels × coefficients floats of each vertex in order, zero-padded to a
// multiple of 4; "albedo" (3 components, linear RGB); "shading" (1
// component, the shading coefficient A, when the transfer has it). A JSON sidecar beside
// it (OUT.glb → OUT.prt.json) says how to read them:
//   {"format": "skybake-prt", "version": 1, "order": 3, "coefficients": 16,
//    "channels": 1, "kind": "shadowed", "model": "prt", "bounces": 0,
//    "rule": "lebedev:590", "albedo": "vertex-colors" | [r, g, b],
//    "vertices": 1234, "attributes": ["prt_0", ...], "colors": "white-sky" (optional)}

// OUT.glb → OUT.prt.json.
std::filesystem::path prt_sidecar_path(const std::filesystem::path& mesh_path);
// Stores the transfer and the albedo on the mesh as attributes.
void set_transfer_attributes(Mesh& mesh, const Transfer& transfer, std::span<const glm::vec3> albedo);
// Sets mesh.colors to what the vertex receives from a uniform white sky, in
// grey, without its albedo: 2√π T_00 (the mean of the channels), clamped to
// [0, 1]. For a shadowed transfer this is the ambient occlusion from the same
// bits (see [SECTION] Definitions); interreflected adds the bounces' light;
// unshadowed is 1. What `prt bake` writes as COLOR_0, like `ao`, so that any
// glTF viewer shows the bake.
void set_white_sky_colors(Mesh& mesh, const Transfer& transfer);
// The sidecar's JSON text. albedo_source: "vertex-colors", or the constant
// albedo as a JSON array "[r, g, b]" (stored as an array).
// white_sky_colors: the mesh's colours are set_white_sky_colors()'s (written
// "colors": "white-sky"); load_prt() then drops them, as they are not a
// colour of the surface (the albedo attribute holds that).
std::string transfer_sidecar_json(const Transfer& transfer, std::size_t vertices, const std::string& albedo_source,
                                  bool white_sky_colors = false);

// Light file (`skybake sky sh`):
//   {"format": "skybake-sh-light", "version": 1, "order": 3,
//    "coefficients": [[r, g, b], ...]  ((order + 1)² of them, sh_index order),
//    "sun_direction": [x, y, z], "sun_irradiance": [r, g, b],
//    "source": "reference" | "network" | ..., "rule": "lebedev:590",
//    "sh_convention": "skybake" | "condon-shortley"}
// The coefficients are written in `convention` (skybake/sh.h, ShConvention)
// and the file says which; load_light() converts them back to skybake's, so
// a file in either convention relights the same. A file without the member
// is in skybake's.
std::string light_json(const ShLight& light, const std::string& source, const std::string& rule,
                       ShConvention convention = ShConvention::Skybake);
// Throws skybake::Error (where: "light") for a missing, corrupt or inconsistent file.
ShLight load_light(const std::filesystem::path& path);
// The same from the file's text (what load_light() reads); `name` stands for
// the file in error messages. Integer fields must be JSON integers.
ShLight light_from_json(std::string_view text, const std::string& name);

struct PrtModel {
    Mesh mesh;
    Transfer transfer;
    std::vector<glm::vec3> albedo;
};
// Reads a mesh written with its sidecar. Throws skybake::Error (where:
// "sidecar") for a missing, corrupt or mismatched sidecar (wrong format,
// order, vertex count or attributes).
PrtModel load_prt(const std::filesystem::path& mesh_path);
// What load_prt() does once both are read: the sidecar's text checked and
// then applied to `mesh` (its prt_N, albedo and shading attributes). The names
// stand for the two files in error messages; throws as load_prt() does.
PrtModel prt_from_sidecar_json(std::string_view sidecar, Mesh mesh, const std::string& sidecar_name,
                               const std::string& mesh_name);

} // namespace skybake
