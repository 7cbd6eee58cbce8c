// skybake/neural.h: the neural sky of Pietras & Rudnicki (seed 000, sections
// III and VI): small multi-layer perceptrons that approximate the sky function
// I(cos α0, cos β0, cos θ0, ρ0) of skybake/sky.h, trained on the CPU, measured
// against the sky model and exported as self-contained shader functions.
//
// [SECTION] Topology
// [SECTION] Output encoding
// [SECTION] The network and its weights file
// [SECTION] Inference
// [SECTION] Training
// [SECTION] Learning curves
// [SECTION] Export to shaders and C
// [SECTION] Accuracy
// [SECTION] Look-up table baseline
// [SECTION] Rendering
//
// See docs/neural.md for the maths, the measured errors and examples.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "skybake/image.h"
#include "skybake/core.h"
#include "skybake/sky.h"

namespace skybake {

// [SECTION] Topology --------------------------------------------------------------
//
// Every network has 4 inputs (cos α0, cos β0, cos θ0, ρ0, as in SkySample) and
// 4 encoded outputs (R, G, B, M; see the encoding below). Every neuron,
// the outputs included, has a bias and the seed's activation
//     f(x) = 1 / (1 + 2^(2x))        (values in (0, 1), f(0) = 0.5).
//
// independent (the seed): four sub-networks, one per output, each
//     4 -> hidden[0] -> ... -> hidden[k-1] -> 1.
// shared: one network 4 -> hidden[0] -> ... -> 4.
// The seed's topology "paper" is independent with hidden = {8, 4}: 81 weights
// per sub-network, 324 in total.
struct NeuralTopology {
    std::vector<int> hidden{8, 4}; // widths of the hidden layers: 1 to 7 layers, each 1 to 128 wide
    bool shared = false;           // false: one independent sub-network per output; true: one with every output
    int outputs = 4;               // encoded outputs (NeuralEncoding::output_count()): 4, or 3 per phase term
    int inputs = 4;                // the sky function's 4 arguments, 5 with an aerosol family's amount

    int subnet_count() const { return shared ? 1 : outputs; }
    int outputs_per_subnet() const { return shared ? outputs : 1; }
    // Weights and biases of one sub-network, and of the whole network.
    int subnet_weight_count() const;
    int weight_count() const { return subnet_count() * subnet_weight_count(); }
    // "paper" (the seed's: independent:8x4 with 4 outputs), "independent:16x16", "shared:64x64".
    std::string name() const;
    // Throws skybake::Error naming `where` when a width or the depth is out of range.
    void validate(const std::string& where = "topology") const;
};

// Parses "paper" (= independent:8x4), "independent:W1xW2x...", "shared:W1xW2x...".
// Throws skybake::Error naming `where` for anything else.
NeuralTopology parse_topology(std::string_view text, const std::string& where = "--topology");

// [SECTION] Output encoding ---------------------------------------------------------
//
// The seed's normalisation (section III): with N = max(I_r, I_g, I_b),
//   R = I_r/N, G = I_g/N, B = I_b/N       (chromaticity, the largest is 1)
//   M = 0.9 N / max{N} + 0.05             (brightness; max{N} over 100,000 random samples)
// and at night (N = 0) M = 0 with R, G, B not trained. The outputs of the
// sigmoid-like activation lie in (0, 1), so every output is trained as
// 0.05 + 0.9 · value; the seed's vertex program decodes all four outputs with
// (x − 0.05)/0.9 and treats x < 0.05 as 0 (section VI, "final transformation").
//
// Brightness "linear" is the paper's linear M. Brightness "log" replaces it with
//   M = 0.05 + 0.9 · max(0, 1 + ln(N / max{N}) / log_range),
// so that a fixed error in M is a fixed *relative* error in N (the sky's
// brightness spans many decades between noon and twilight).
enum class BrightnessEncoding : int {
    Linear = 0, // "linear" (files may say "seed"): M = 0.05 + 0.9 · N / max{N}, as Pietras & Rudnicki print it
    Log = 1,  // logarithmic over log_range nats below max{N}
};

// "linear" or "log"; parse_brightness_encoding() also takes the older "seed"
// for Linear, and throws skybake::Error naming `where` otherwise.
const char* brightness_encoding_name(BrightnessEncoding encoding);
BrightnessEncoding parse_brightness_encoding(const std::string& text, const std::string& where = "brightness");

// Inputs. "seed": (cos α0, cos β0, cos θ0, ρ0) as they are. "horizon": the
// view ray's length to the top or to the ground, split at the horizon as in
// Bruneton 2017's texture mapping (up rays in [0, 1], ground rays in [−1, 0],
// the horizon at +1 and −1: the cliff's two sides far apart), cos β0, cos θ0,
// and Bruneton's altitude coordinate 2√(r² − R0²)/√(Rtop² − R0²) − 1 (the
// formulas: src/neural/mlp_hd.h, encode_inputs). The geometry comes from the
// network's atmosphere.
enum class InputEncoding : int { Seed = 0, Horizon = 1 };
// Outputs. "radiance": the seed's R/N, G/N, B/N and brightness M (4
// outputs). "phase-factored": in single scattering with a parallel sun, cos β
// is the same along the whole view ray, so I = Σ_k P_k(cos β0) S_k exactly,
// with S_k the in-scatter integral of scattering component k without its
// phase function. The network learns each S_k per channel (3 outputs per
// scattering component, each log-encoded over log_range below its own
// maximum); the exact phase functions are applied outside it. "residual":
// the phase-factored terms as corrections of an analytic single scattering,
// a few-step march over the view ray's lit parts with Chapman-function sun
// depths (src/neural/mlp_hd.h, analytic_terms): per term and channel the log
// of S_k over the march's A_k. The march carries the decades (altitude, the
// planet's shadow); the network the few tens of percent it misses. With
// multiple scattering, three more outputs carry the light scattered more than
// once (NeuralEncoding::multiple). The terms' components must have
// exponential profiles.
enum class OutputEncoding : int { Radiance = 0, PhaseFactored = 1, Residual = 2 };
// Phase-factored and residual outputs: one term per scattering component.
inline bool has_phase_terms(OutputEncoding e) { return e != OutputEncoding::Radiance; }
// The outputs `sky train` and train_sky() choose when none are asked for:
// residual where every scattering component is exponential, else
// phase-factored for single scattering and radiance with multiple.
OutputEncoding default_output_encoding(const Atmosphere& atmosphere);
const char* input_encoding_name(InputEncoding encoding);
const char* output_encoding_name(OutputEncoding encoding);
InputEncoding parse_input_encoding(const std::string& text, const std::string& where = "inputs");
OutputEncoding parse_output_encoding(const std::string& text, const std::string& where = "outputs");

// One phase-factored term: a scattering component of the atmosphere.
struct PhaseTerm {
    std::string component;       // its name in the atmosphere ("rayleigh", "mie")
    PhaseFunction phase = PhaseFunction::Rayleigh;
    double g = 0.0;
    glm::dvec3 max_s{1.0};       // per channel, the largest S_k over the max{N} samples (1/km · km = 1)
};

struct NeuralEncoding {
    InputEncoding inputs = InputEncoding::Seed;
    OutputEncoding outputs = OutputEncoding::Radiance;
    BrightnessEncoding brightness = BrightnessEncoding::Log; // Radiance only; phase-factored outputs are log
    double max_n = 1.0;      // max{N} over the max_n samples, radiance per unit sun irradiance (1/sr); > 0
    double log_range = 13.815510557964274; // Log: nats of N/max{N} (or S/max S) mapped onto [0.05, 0.95] (ln 1e6)
    std::vector<PhaseTerm> terms; // PhaseFactored and Residual: one per scattering component, 1 to 4

    // Encoded outputs: 4 (radiance) or 3 per term.
    // Residual outputs of a sky with multiple scattering: three more outputs,
    // the light scattered more than once (the total less the single
    // scattering), log-encoded per channel like a phase-factored term, below
    // multiple_max (the largest over the max{N} samples) over 12 decades
    // (kMultipleLogRange in src/neural/mlp_hd.h).
    bool multiple = false;
    glm::dvec3 multiple_max{1.0};
    // Or, with multiple_psi set, the term is a correction of an isotropic
    // march (Hillaire 2020's approximation, src/neural/mlp_hd.h's
    // analytic_multiple) by a factor within e^±2: ln ψ per channel, the sky's
    // mean radiance around a point, as a polynomial of degrees 2 in altitude
    // and 6 in the sun's cosine (3 × 21 coefficients, r then g then b), over
    // sun cosines from multiple_psi_mu_min to 1. Empty: log-encoded as above
    // (multiple_max is then what decodes it).
    std::vector<double> multiple_psi;
    double multiple_psi_mu_min = -0.5;
    bool multiple_marched() const { return !multiple_psi.empty(); }
    // An atmosphere family (residual outputs of single scattering): the
    // amount of one scattering component, the aerosol, is a fifth input,
    // chosen at run time (NeuralSky::aerosol) as a multiple of the
    // atmosphere's within [aerosol_min, aerosol_max]. The analytic march
    // scales that component's coefficients by it; the network learns the
    // rest. family_component empty: no family (four inputs).
    std::string family_component;
    double aerosol_min = 1.0, aerosol_max = 1.0;
    bool has_family() const { return !family_component.empty(); }
    int input_count() const { return has_family() ? 5 : 4; }
    int output_count() const {
        return outputs == OutputEncoding::Radiance ? 4 : 3 * int(terms.size()) + (multiple ? 3 : 0);
    }
};

// Encoded target (4 values in [0, 1]) of a radiance, and the radiance of 4
// encoded outputs. Exposed for tests and for users who write their own decoder.
void encode_sky_radiance(const NeuralEncoding& encoding, const glm::vec3& radiance, float encoded[4]);
glm::vec3 decode_sky_radiance(const NeuralEncoding& encoding, const float encoded[4]);

// [SECTION] The network and its weights file ------------------------------------------
//
// Weight layout (flat, float): sub-network s starts at s * subnet_weight_count();
// inside it, for each layer l (inputs → hidden[0] → ... → outputs) the matrix
// W_l, row-major [out][in], then the biases b_l [out]. A layer computes
// a_out = f(W_l a_in + b_l). Sub-networks of the independent topology are in
// the order R, G, B, M.
struct NeuralTrainingSummary {
    std::uint64_t samples = 0;         // training samples
    std::uint64_t heldout_samples = 0; // held-out samples for the learning curve
    std::uint64_t seed = 0;            // sampling and initialisation seed
    int adam_epochs = 0;               // epochs of Adam
    int lm_iterations = 0;             // Levenberg–Marquardt iterations run
    double seconds = 0.0;              // wall-clock training time, data generation included
    int threads = 0;                   // worker threads used
    double train_rms = 0.0;            // RMS error of the encoded outputs, training set, at the end
    double heldout_rms = 0.0;          // same, held-out set
    double heldout_mean_relative = 0.0; // mean |ΔI|/|I| on the held-out samples with N > 0
};

// Settings of the sky model the network was trained on (SkyModelOptions).
struct NeuralSky {
    NeuralTopology topology;
    NeuralEncoding encoding;
    std::vector<float> weights;        // topology.weight_count() floats, layout above
    Atmosphere atmosphere;             // the atmosphere it was trained on
    SkyModelOptions sky_options;       // tables and steps of the training targets
    NeuralTrainingSummary training;
    // Run time, not saved: the aerosol amount of a family network, as a
    // multiple of its atmosphere's, in [encoding.aerosol_min, aerosol_max];
    // must be 1 for a network without a family. Every evaluator follows it
    // (the CPU and CUDA passes, the renderers, the uniform block).
    double aerosol = 1.0;

    // Throws skybake::Error naming `where` if the topology, the weight count,
    // a weight or an encoding constant is invalid.
    void validate(const std::string& where = "neural sky") const;
};

// JSON (format "skybake-neural-sky", version 2) <-> NeuralSky. Parsing
// validates everything and throws skybake::Error naming `where` and the field.
// Version 1 files (the seed's inputs and outputs, before encodings were
// selectable) still load, and give the same outputs.
std::string neural_sky_to_json(const NeuralSky& net);
NeuralSky neural_sky_from_json(std::string_view text, const std::string& where = "weights JSON");
NeuralSky load_neural_sky(const std::filesystem::path& path);
void save_neural_sky(const std::filesystem::path& path, const NeuralSky& net); // atomic write

// The reference model the network approximates (its atmosphere and options;
// for an aerosol family, the atmosphere at the network's aerosol amount).
SkyModel neural_reference_model(const NeuralSky& net);

// [SECTION] Inference ---------------------------------------------------------------
//
// Radiance per unit sun irradiance, 1/sr, as SkyModel::radiance. Samples must
// be valid (is_valid_sky_sample; asserted). out.size() must equal samples.size().
// Batch inference is vectorised (Eigen) and uses all cores; deterministic.
void evaluate_neural_sky(const NeuralSky& net, std::span<const SkySample> samples, std::span<glm::vec3> out);
// The same on CUDA device 0: weights in constant memory, the seed's topology
// fully unrolled with the activation on the special-function unit (agrees
// with evaluate_neural_sky to 1e-5 relative), other topologies through the
// shared forward pass. Throws skybake::Error without CUDA or a device.
void evaluate_neural_sky_cuda(const NeuralSky& net, std::span<const SkySample> samples, std::span<glm::vec3> out);
// One sample through the scalar forward pass that shaders and CUDA share
// (sets up the layout on every call: use evaluate_neural_sky for many samples).
glm::vec3 neural_sky_radiance(const NeuralSky& net, const SkySample& sample);
// The encoded outputs of the scalar forward pass (R, G, B, M; or 3 per phase term).
void neural_sky_encoded(const NeuralSky& net, const SkySample& sample, float* encoded); // topology.outputs values

// [SECTION] Training ------------------------------------------------------------------
//
// Samples are drawn uniformly over the valid part of [−1,1]³ × (0,1]
// (draw_sky_samples: rejection of cosine triples with a negative Gram
// determinant); targets come from SkyModel's table path (evaluate_sky).
// Adam with an exponentially decaying learning rate on shuffled mini-batches,
// then Levenberg–Marquardt on each sub-network. Deterministic for a given
// seed, whatever the thread count.
// The targets `skybake sky train` and skybake.train_sky() learn from by
// default: the table path with the refined shell rule (TableRule::Refined),
// these tables and this many graded steps along each view ray. On `earth` it
// is within 0.15% (mean) and 1.0% (p99) of the exact quadrature, against
// 1.7% and 7.6% for the seed's rule at 256 × 128 and 16 steps (docs/neural.md,
// "Training targets").
inline constexpr int kTrainingTargetSteps = 64;
// The topology `skybake sky train` uses without --topology: with the horizon
// inputs and phase-factored outputs it is the most accurate network of at most
// 400 weights we measured (docs/neural.md, "Size and accuracy").
inline constexpr const char* kDefaultTopology = "shared:16x12";
inline constexpr TableResolution kTrainingTargetTables{512, 256};

// The training schedule measured for a topology's size (docs/neural.md,
// "Training"), by its widest hidden layer: up to 16 wide 60 Adam epochs from
// a step of 0.02 and 20 Levenberg–Marquardt iterations (the default); up to
// 32, 60 epochs and 3 iterations; up to 64, 150 epochs from 0.01 and no LM
// (the normal equations cost rows × P² and stop paying); wider, 30 epochs
// from 0.005 (at 0.02 their outputs die). `sky train` and train_sky() use it
// for whatever is not asked for.
struct NeuralSchedule {
    int adam_epochs = 60;
    double learning_rate = 0.02;
    int lm_iterations = 20;
};
NeuralSchedule training_schedule(const NeuralTopology& topology);

struct NeuralTrainOptions {
    NeuralTopology topology;                 // its `outputs` is set from the encoding
    InputEncoding inputs = InputEncoding::Seed;
    OutputEncoding outputs = OutputEncoding::Radiance; // PhaseFactored needs single scattering
    BrightnessEncoding brightness = BrightnessEncoding::Log;
    double log_range = 13.815510557964274;   // nats (Log only)
    std::size_t samples = 800000;            // training samples
    std::size_t heldout_samples = 20000;     // held-out samples for the learning curve
    std::size_t max_n_samples = 100000;      // samples for max{N} (the seed's 100,000)
    std::uint64_t seed = 1;
    int adam_epochs = 60;
    std::size_t batch = 1024;                // Adam mini-batch
    double learning_rate = 0.02;             // Adam, first epoch
    double learning_rate_final = 0.0005;     // Adam, last epoch (exponential decay between)
    int lm_iterations = 20;                  // Levenberg–Marquardt iterations; 0 skips it
    std::size_t lm_samples = 0;              // samples in the LM least squares; 0: automatic (train.cpp)
    bool progress = true;                    // progress bar on stderr (TTY only)
    // Where the training targets are computed: Device::Cuda runs the sky
    // model's table path on the GPU (evaluate_sky_cuda); the optimiser runs
    // on the CPU either way.
    Device device = Device::Cpu;
    // An aerosol family (NeuralEncoding::family_component): each sample's
    // amount of this component is drawn log-uniformly in [aerosol_min,
    // aerosol_max] times the atmosphere's. Empty: one atmosphere.
    std::string family_component;
    double aerosol_min = 1.0, aerosol_max = 1.0;
    // Importance sampling: this share of the training samples (not the
    // held-out ones) is drawn where the sky is hard instead of uniformly: a
    // third each near the horizon, the sun's aureole and the terminator.
    double hard_share = 0.0;
    // This share of the training samples (after the hard ones) is drawn as a
    // flight's (draw_flight_samples: altitude uniform to 60 km, the sun down to
    // −20°), whose high, dim twilight the uniform samples barely reach. −1:
    // automatic, 0.4 with multiple scattering (where it pays: docs/neural.md)
    // and 0 for single scattering (where it does not).
    double flight_share = -1.0;
    // Residual outputs with multiple scattering: the term as a correction of
    // an isotropic march (NeuralEncoding::multiple_psi), or, false, log-encoded.
    bool multiple_march = true;
};

// One point of the learning curve: after Adam epoch `epoch` (phase "adam") or
// after LM iteration `epoch − adam_epochs` (phase "lm").
struct LearningCurvePoint {
    int epoch = 0;
    std::string phase;
    double train_rms = 0.0;        // RMS error of the encoded outputs on the training set (Adam: mean over the
                                   // epoch's mini-batches as they were trained; LM: after the iteration)
    double heldout_rms = 0.0;      // same on the held-out set
    double heldout_mean_relative = 0.0; // mean |ΔI|/|I| on held-out samples with N > 0
    double seconds = 0.0;          // since training started
};

NeuralSky train_neural_sky(const SkyModel& model, const NeuralTrainOptions& options,
                           std::vector<LearningCurvePoint>* curve = nullptr);

// [SECTION] Learning curves ------------------------------------------------------------
// CSV: epoch,phase,train_rms,heldout_rms,heldout_mean_relative,seconds.
void save_learning_curve_csv(const std::filesystem::path& path, const std::vector<LearningCurvePoint>& curve);
// One labelled curve on a chart.
struct ChartSeries {
    std::string label;
    glm::vec3 colour{0.0f};      // linear RGB in [0, 1]
    std::vector<double> x, y;    // y > 0 (log scale); equal sizes
};
// A line chart with a logarithmic y axis, ticks and labels drawn with a
// built-in 5x7 font; linear RGB in [0, 1] (save with ToneCurve::Clamp).
Image draw_line_chart(const std::vector<ChartSeries>& series, const std::string& title, const std::string& x_label,
                      const std::string& y_label, int width = 800, int height = 500);
// Training and held-out RMS against epoch, as PNG.
void save_learning_curve_png(const std::filesystem::path& path, const std::vector<LearningCurvePoint>& curve,
                             const std::string& title);

// [SECTION] Export to shaders and C -------------------------------------------------------
//
// A self-contained function with the weights baked in as constants:
//   GLSL: vec3   NAME(float cos_view_zenith, float cos_view_sun, float cos_sun_zenith, float density)
//   HLSL: float3 NAME(...)
//   CUDA: __host__ __device__ void NAME(..., float rgb[3])  (also plain C++ without nvcc)
//   C:    void NAME(..., float rgb[3])                       (C99, needs <math.h>)
// It returns radiance per unit sun irradiance (1/sr); it works in vertex and
// fragment shaders (no uniforms, no textures). All arithmetic is float.
// GlslEs: GLSL ES 3.00 (WebGL 2), computing in highp whatever the shader's default precision.
enum class ExportLanguage : int { Glsl = 0, Hlsl = 1, Cuda = 2, C = 3, GlslEs = 4 };
ExportLanguage parse_export_language(std::string_view text, const std::string& where = "--format");
std::string export_neural_sky(const NeuralSky& net, ExportLanguage language,
                              const std::string& function_name = "skybake_sky");

// GLSL with the weights read from a uniform block instead of constants:
//   layout(std140) uniform BLOCK { vec4 NAME_w[K]; };
// holding the weights in the layout above, then max{N} and log_range
// (neural_sky_uniform_data). The text then depends only on the topology and
// the brightness encoding, so new weights of the same kind need no new
// shader: upload them with neural_sky_uniform_data. Other languages ignore it.
struct ShaderExportOptions {
    std::string function_name = "skybake_sky";
    bool uniform_block = false;
    std::string block_name = "SkybakeSkyWeights"; // a valid identifier
};
std::string export_neural_sky(const NeuralSky& net, ExportLanguage language, const ShaderExportOptions& options);
// Whether `name` can name a function or block in every exported language:
// 1 to 64 letters, digits and '_', not starting with a digit or "gl_".
bool valid_shader_identifier(const std::string& name);
// The contents of that uniform block: 4 * K floats (K vec4s, zero-padded).
std::vector<float> neural_sky_uniform_data(const NeuralSky& net);

// [SECTION] Accuracy -------------------------------------------------------------------------
//
// Relative RGB error |ΔI|/|I| (Euclidean norms over R, G, B) on held-out
// valid samples, split by the reference radiance:
//   day:      the sun above the observer's horizon (cos θ0 > 0) and N > 0,
//   twilight: the sun below it (cos θ0 ≤ 0) and N > 0,
//   night:    N = 0 (the whole view ray in the planet's shadow); relative
//             error is undefined there, so the absolute error |ΔI| / max{N} is reported.
struct ErrorStats {
    std::size_t count = 0;
    double mean = 0.0, p50 = 0.0, p95 = 0.0, p99 = 0.0, max = 0.0;
};
// Statistics of a list of errors (sorted in place).
ErrorStats error_stats(std::vector<double>& errors);

struct ViewPsnr {
    std::string name;
    double psnr_db = 0.0; // of the tone-mapped sRGB image against the reference's
};

struct NeuralErrorReport {
    ErrorStats all, day, twilight; // relative errors
    ErrorStats night;              // |ΔI| / max{N}
    // The same over the samples of a flight (draw_flight_samples: altitude
    // uniform from 0 to 60 km, the sun down to −20°), where a flight from the
    // ground to space spends its time; empty with flight_samples = 0.
    ErrorStats flight_all, flight_day, flight_twilight, flight_night;
    std::vector<ViewPsnr> views;
    double mean_view_psnr_db = 0.0;
    double min_view_psnr_db = 0.0;
};

struct NeuralErrorOptions {
    std::size_t samples = 100000;
    std::uint64_t seed = 0x5eed000e77;  // distinct from the training streams
    std::size_t flight_samples = 100000; // draw_flight_samples, from the same seed; 0: none
    FlightSampling flight;
    bool views = true;                  // render the seed's views and compare
    int view_width = 240, view_height = 160;
    std::filesystem::path views_dir;    // when not empty: write NAME_reference.png and NAME_neural.png there
};

NeuralErrorReport measure_neural_sky_error(const NeuralSky& net, const NeuralErrorOptions& options = {});

// [SECTION] Look-up table baseline -------------------------------------------------------------
//
// What a network must beat: a plain 4D table over the same inputs (the
// network's input encoding), holding the same encoded outputs at its nodes,
// interpolated quadrilinearly, as Bruneton 2017 stores its sky. Its nodes are
// the linear least-squares fit to the training targets (the best table of its
// size for the network's own loss; a small ridge term keeps nodes that no
// sample reaches at 0). Used for the size–accuracy curve of docs/neural.md.
struct SkyLookupTable {
    NeuralEncoding encoding;
    Atmosphere atmosphere;          // for the input encoding and the reference
    SkyModelOptions sky_options;
    std::array<int, 4> size{};      // nodes per input, ≥ 2 each
    std::array<float, 4> lo{}, hi{}; // range of each input covered by the nodes
    std::vector<float> values;      // per node (input 0 fastest), the encoded outputs
    std::size_t float_count() const { return values.size(); }
};
// A table of at most `floats` values (4 bytes each, like a network's
// weights) with the encodings of `options`, fitted on options.samples
// targets of `model`'s table path. Throws skybake::Error naming `floats` when
// not even 2^4 nodes fit.
SkyLookupTable fit_sky_lookup_table(const SkyModel& model, const NeuralTrainOptions& options, std::size_t floats);
void evaluate_sky_lookup_table(const SkyLookupTable& table, std::span<const SkySample> samples,
                               std::span<glm::vec3> out);
// measure_neural_sky_error for the table (against the same reference model).
NeuralErrorReport measure_sky_lookup_table_error(const SkyLookupTable& table, const NeuralErrorOptions& options = {});

// [SECTION] Rendering --------------------------------------------------------------------------
//
// The seed's views (section VII): sea level, higher and higher, low sun, very
// high. Camera views; the atmosphere is the network's.
struct PublishedView {
    std::string name;
    SkyRenderSettings settings;
};
std::vector<PublishedView> published_views(int width, int height);

// As render_sky, with the sky and the in-scattered light in front of the ground
// from the network (the seed's section III), and the ground and the sun disc
// from the tables of `tables` (section IV; build it with neural_reference_model).
// settings.method is ignored.
Image render_neural_sky(const NeuralSky& net, const SkyModel& tables, const SkyRenderSettings& settings);
// The same on CUDA device 0 (same per-pixel code); throws without CUDA or a device.
Image render_neural_sky_cuda(const NeuralSky& net, const SkyModel& tables, const SkyRenderSettings& settings);

// PSNR in dB of two images of the same size after tone mapping both with tm
// and the sRGB transfer function (display values in [0, 1], not quantised).
// A NaN or infinite value counts as the largest error, 1; identical images
// give 999 dB.
double image_psnr_db(const Image& reference, const Image& test, const ToneMap& tm);

} // namespace skybake
