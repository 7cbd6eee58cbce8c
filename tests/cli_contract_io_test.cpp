// The command line's contract, table-driven: every numeric flag of every
// sub-command fed NaN, infinities, huge, non-numeric and (where they are not
// allowed) negative and zero values; every output flag pointed at a missing
// folder and at a folder nobody can write; SIGTERM and SIGINT in the middle of
// a bake and of an import. Each case: the exit code, exactly one line on
// stderr, and no output file (or an existing one unchanged).
//
// A new flag is covered by adding one row to kNumericFlags or kOutputFlags.
// Label "io": this also runs under AddressSanitizer + UBSan.
#include <algorithm>
#include <cctype>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli_runner.h"
#include "core/test_paths.h"

using skybake::test::CliResult;
using skybake::test::run_cli;
namespace fs = std::filesystem;

namespace {

// The shared inputs, made once: a small mesh, a sky CSV, a tiny weights file
// and a batch list naming the mesh.
struct Inputs {
    std::string dir, mesh, csv, model, list;
};

const Inputs& inputs() {
    static const Inputs in = [] {
        Inputs i;
        i.dir = skybake::test::temp_dir("contract-inputs");
        i.mesh = i.dir + "/wall.glb";
        EXPECT_EQ(run_cli({"mesh", "generate", "--kind", "wall", "--triangles", "200", "-o", i.mesh}).exit_code, 0);
        i.csv = i.dir + "/samples.csv";
        std::ofstream(i.csv) << "cos_view_zenith,cos_view_sun,cos_sun_zenith,density\n1,1,1,1\n";
        i.list = i.dir + "/assets.txt";
        std::ofstream(i.list) << "# the mesh\n" << i.mesh << "\n";
        i.model = i.dir + "/tiny.json";
        const CliResult t = run_cli({"sky", "train", "--samples", "200", "--heldout", "50", "--epochs", "1",
                                     "--lm-iterations", "0", "-q", "-o", i.model});
        EXPECT_EQ(t.exit_code, 0) << t.err;
        return i;
    }();
    return in;
}

// {in}, {csv}, {model}, {list} and {out} in a command are replaced by the inputs and
// by the case's output folder.
std::vector<std::string> expand(const std::vector<std::string>& cmd, const std::string& out) {
    std::vector<std::string> r;
    for (std::string a : cmd) {
        for (const auto& [key, value] : {std::pair<std::string, std::string>{"{in}", inputs().mesh},
                                         {"{csv}", inputs().csv},
                                         {"{model}", inputs().model},
                                         {"{list}", inputs().list},
                                         {"{out}", out}}) {
            const auto p = a.find(key);
            if (p != std::string::npos)
                a.replace(p, key.size(), value);
        }
        r.push_back(a);
    }
    return r;
}

std::string describe(const std::vector<std::string>& args) {
    std::string s = "skybake";
    for (const auto& a : args)
        s += " " + a;
    return s;
}

void expect_refused(const CliResult& r, int code, const std::string& needle, const std::string& what) {
    EXPECT_EQ(r.signal, 0) << what << ": crashed with signal " << r.signal;
    EXPECT_EQ(r.exit_code, code) << what << "\n" << r.err;
    EXPECT_EQ(r.err_lines(), 1) << what << "\n" << r.err;
    EXPECT_EQ(r.err.rfind("skybake: error: ", 0), 0u) << what << "\n" << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << what << ": the message should name " << needle << "\n" << r.err;
}

// Files in a folder (the outputs a failed command must not leave, temporary ones included).
std::vector<std::string> files_in(const std::string& dir) {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir))
        names.push_back(e.path().filename().string());
    return names;
}

struct NumericFlag {
    std::vector<std::string> command; // a valid command without the flag; {out} is an empty folder
    const char* flag;
    bool negative_ok, zero_ok; // whether -1 and 0 are legal values
};

// Every numeric flag of every sub-command.
const NumericFlag kNumericFlags[] = {
    {{"mesh", "generate", "-o", "{out}/m.glb"}, "--triangles", false, false},
    {{"mesh", "generate", "-o", "{out}/m.glb"}, "--seed", false, true},
    {{"ao", "{in}", "-o", "{out}/a.glb"}, "--max-distance", false, false},
    {{"ao", "{in}", "-o", "{out}/a.glb"}, "--offset", false, true},
    {{"ao", "{in}", "-o", "{out}/a.glb", "--texture", "64"}, "--uv", false, true},
    {{"ao", "{in}", "-o", "{out}/a.glb", "--texture", "64"}, "--dilate", false, true},
    {{"ao", "{in}", "-o", "{out}/a.glb", "--preview", "{out}/p.png"}, "--preview-azimuth", true, true},
    {{"ao", "{in}", "-o", "{out}/a.glb", "--preview", "{out}/p.png"}, "--preview-elevation", true, true},
    {{"sky", "optical-length", "--cos-zenith", "1"}, "--density", false, false},
    {{"sky", "optical-length", "--density", "1"}, "--cos-zenith", true, true},
    {{"sky", "optical-length", "--density", "1", "--cos-zenith", "1"}, "--component", false, true},
    {{"sky", "optical-length", "--density", "1", "--cos-zenith", "1"}, "--shells", false, false},
    {{"sky", "optical-length", "--density", "1", "--cos-zenith", "1"}, "--cosines", false, false},
    {{"sky", "optical-length", "--preset", "paper", "--density", "1", "--cos-zenith", "1"}, "--paper-r", false, false},
    {{"sky", "optical-length", "--preset", "paper", "--density", "1", "--cos-zenith", "1"}, "--paper-m", false, false},
    {{"sky", "eval", "--input", "{csv}", "--output", "{out}/o.csv"}, "--steps", false, false},
    {{"sky", "eval", "--input", "{csv}", "--output", "{out}/o.csv"}, "--shells", false, false},
    {{"sky", "eval", "--input", "{csv}", "--output", "{out}/o.csv"}, "--cosines", false, false},
    {{"sky", "render", "--sun-elevation-deg", "10", "--size", "8x8", "-o", "{out}/r.png"},
     "--altitude-km",
     false,
     true},
    {{"sky", "render", "--altitude-km", "0", "--size", "8x8", "-o", "{out}/r.png"}, "--sun-elevation-deg", true, true},
    {{"sky", "render", "--altitude-km", "0", "--sun-elevation-deg", "10", "--size", "8x8", "-o", "{out}/r.png"},
     "--sun-azimuth-deg",
     true,
     true},
    {{"sky", "render", "--altitude-km", "0", "--sun-elevation-deg", "10", "--view", "camera", "--size", "8x8", "-o",
      "{out}/r.png"},
     "--fov",
     false,
     false},
    {{"sky", "render", "--altitude-km", "0", "--sun-elevation-deg", "10", "--view", "camera", "--size", "8x8", "-o",
      "{out}/r.png"},
     "--yaw",
     true,
     true},
    {{"sky", "render", "--altitude-km", "0", "--sun-elevation-deg", "10", "--view", "camera", "--size", "8x8", "-o",
      "{out}/r.png"},
     "--pitch",
     true,
     true},
    {{"sky", "render", "--altitude-km", "0", "--sun-elevation-deg", "10", "--size", "8x8", "-o", "{out}/r.png"},
     "--steps",
     false,
     false},
    {{"sky", "render", "--altitude-km", "0", "--sun-elevation-deg", "10", "--size", "8x8", "-o", "{out}/r.png"},
     "--exposure",
     true,
     true},
    {{"sky", "render", "--altitude-km", "0", "--sun-elevation-deg", "10", "--view", "camera", "--renderer", "gl",
      "--size", "8x8", "-o", "{out}/r.png"},
     "--max-error-px",
     false,
     false},
    {{"sky", "render", "--altitude-km", "0", "--sun-elevation-deg", "10", "--view", "camera", "--renderer", "gl",
      "--size", "8x8", "-o", "{out}/r.png"},
     "--max-triangles",
     false,
     false},
    {{"fly", "--model", "{model}", "--size", "8x8", "-o", "{out}"}, "--frames", false, false},
    {{"fly", "--model", "{model}", "--size", "8x8", "-o", "{out}"}, "--max-error-px", false, false},
    {{"fly", "--model", "{model}", "--size", "8x8", "-o", "{out}"}, "--max-triangles", false, false},
    {{"fly", "--model", "{model}", "--size", "8x8", "-o", "{out}"}, "--relief", false, true},
    {{"fly", "--model", "{model}", "--size", "8x8", "-o", "{out}"}, "--exposure", true, true},
    {{"fly", "--model", "{model}", "--size", "8x8", "-o", "{out}", "--mp4", "{out}/f.mp4"}, "--fps", false, false},
    {{"view", "planet", "--model", "{model}"}, "--altitude-km", false, false},
    {{"view", "planet", "--model", "{model}"}, "--sun-elevation-deg", true, true},
    {{"view", "planet", "--model", "{model}"}, "--sun-azimuth-deg", true, true},
    {{"view", "planet", "--model", "{model}"}, "--exposure", true, true},
    {{"sky", "train", "-o", "{out}/w.json"}, "--samples", false, false},
    {{"sky", "train", "-o", "{out}/w.json"}, "--log-range", false, false},
    {{"sky", "train", "-o", "{out}/w.json"}, "--epochs", false, true},
    {{"sky", "train", "-o", "{out}/w.json"}, "--lm-iterations", false, true},
    {{"sky", "train", "-o", "{out}/w.json"}, "--lm-samples", false, true},
    {{"sky", "train", "-o", "{out}/w.json"}, "--batch", false, false},
    {{"sky", "train", "-o", "{out}/w.json"}, "--learning-rate", false, false},
    {{"sky", "train", "-o", "{out}/w.json"}, "--learning-rate-final", false, false},
    {{"sky", "train", "-o", "{out}/w.json"}, "--heldout", false, false},
    {{"sky", "train", "-o", "{out}/w.json"}, "--seed", false, true},
    {{"sky", "train", "-o", "{out}/w.json"}, "--steps", false, false},
    {{"sky", "error", "--model", "{model}", "--no-views"}, "--samples", false, false},
    {{"sky", "error", "--model", "{model}", "--no-views"}, "--seed", false, true},
    {{"sky", "preset", "paper"}, "--paper-r", false, false},
    {{"sky", "preset", "paper"}, "--paper-m", false, false},
    {{"sphere", "show", "lebedev:6"}, "--limit", false, true},
    {{"sphere", "list"}, "--threads", false, true},
    {{"prt", "bake", "{in}", "-o", "{out}/p.glb"}, "--order", false, true},
    {{"prt", "bake", "{in}", "-o", "{out}/p.glb"}, "--bounces", false, true},
    {{"prt", "bake", "{in}", "-o", "{out}/p.glb"}, "--max-distance", false, false},
    {{"prt", "relight", "{in}", "-o", "{out}/r.png"}, "--sun-elevation-deg", true, true},
    {{"prt", "relight", "{in}", "-o", "{out}/r.png"}, "--sun-azimuth-deg", true, true},
    {{"prt", "relight", "{in}", "-o", "{out}/r.png"}, "--altitude-km", false, true},
    {{"prt", "relight", "{in}", "--light", "constant", "-o", "{out}/r.png"}, "--radiance", false, true},
    {{"prt", "relight", "{in}", "-o", "{out}/r.png"}, "--glossy", false, true},
    {{"prt", "relight", "{in}", "-o", "{out}/r.png"}, "--specular", false, true},
    {{"sky", "sh", "-o", "{out}/l.json"}, "--sun-elevation-deg", true, true},
    {{"sky", "sh", "-o", "{out}/l.json"}, "--sun-azimuth-deg", true, true},
    {{"sky", "sh", "-o", "{out}/l.json"}, "--altitude-km", false, true},
    {{"sky", "sh", "-o", "{out}/l.json"}, "--order", false, true},
    {{"prt", "export", "-o", "{out}/p.glsl"}, "--order", false, true},
    {{"prt", "export", "-o", "{out}/p.glsl"}, "--channels", false, false},
    {{"prt", "export", "--model", "{model}", "-o", "{out}/p.glsl"}, "--glossy", false, false},
    {{"prt", "export", "--model", "{model}", "--glossy", "8", "-o", "{out}/p.glsl"}, "--nodes", false, false},
    {{"ao", "{in}", "-o", "{out}/a.glb"}, "--texture", false, false},
};

// The command a row belongs to ("sky render", "ao"): the table is run one
// command per test, so that no single test runs hundreds of processes (each
// takes about a second under the sanitizers).
std::string command_of(const NumericFlag& f) {
    std::string name = f.command[0];
    if (f.command.size() > 1 && f.command[1].find_first_of("{-") != 0)
        name += " " + f.command[1];
    return name;
}

std::vector<std::string> numeric_commands() {
    std::vector<std::string> names;
    for (const NumericFlag& f : kNumericFlags)
        if (std::find(names.begin(), names.end(), command_of(f)) == names.end())
            names.push_back(command_of(f));
    return names;
}

class NumericFlags : public testing::TestWithParam<std::string> {};

} // namespace

TEST(CliContract, EveryNumericFlagRowBelongsToACommandThatIsTested) {
    // Guards the split: every row is reached by exactly one instance below.
    std::size_t rows = 0;
    for (const std::string& c : numeric_commands())
        for (const NumericFlag& f : kNumericFlags)
            rows += command_of(f) == c;
    EXPECT_EQ(rows, std::size(kNumericFlags));
    EXPECT_GE(numeric_commands().size(), 10u);
}

TEST_P(NumericFlags, RejectWhatIsNotANumberInRange) {
    // None of these commands may start work: a value that slipped through
    // would make some of them (sky train with its defaults) run for minutes,
    // hence the short timeout.
    int cases = 0;
    for (const NumericFlag& f : kNumericFlags) {
        if (command_of(f) != GetParam())
            continue;
#if defined(SKYBAKE_ASAN)
        // Under the sanitizers every run costs about a second: one value of
        // each kind (the validators take the same path for the others).
        std::vector<std::string> values = {"nan", "-inf", "1e300", "1x", ""};
#else
        std::vector<std::string> values = {"nan", "NaN", "inf", "-inf", "1e300", "1e400", "abc", "1x", "0x10", ""};
#endif
        if (!f.negative_ok)
            values.push_back("-1");
        if (!f.zero_ok)
            values.push_back("0");
        for (const std::string& v : values) {
            const std::string out = skybake::test::temp_dir("contract-numeric");
            std::vector<std::string> args = expand(f.command, out);
            args.push_back(f.flag);
            args.push_back(v);
            const CliResult r = run_cli(args, 30);
            expect_refused(r, 2, f.flag, describe(args));
            EXPECT_TRUE(r.out.empty()) << describe(args) << ": " << r.out;
            EXPECT_TRUE(files_in(out).empty()) << describe(args) << " left " << files_in(out).front();
            ++cases;
        }
    }
    EXPECT_GT(cases, 0);
    std::printf("%s: %d numeric-flag cases\n", GetParam().c_str(), cases);
}

INSTANTIATE_TEST_SUITE_P(CliContract, NumericFlags, testing::ValuesIn(numeric_commands()),
                         [](const testing::TestParamInfo<std::string>& info) {
                             std::string name = info.param;
                             for (char& c : name)
                                 if (!std::isalnum(static_cast<unsigned char>(c)))
                                     c = '_';
                             return name;
                         });

namespace {

struct OutputFlag {
    std::vector<std::string> command; // writes `path` through `flag`; {out} is its output folder
    const char* flag;
    const char* file; // the file name the flag is given (in {out}, or in a missing or unwritable folder)
};

// Every flag that names an output.
const OutputFlag kOutputFlags[] = {
    {{"mesh", "generate", "--triangles", "20"}, "-o", "m.glb"},
    {{"mesh", "convert", "{in}"}, "-o", "m.ply"},
    {{"ao", "{in}", "--rule", "lebedev:6"}, "-o", "a.glb"},
    {{"ao", "{in}", "--rule", "lebedev:6", "-o", "{out}/a.glb"}, "--preview", "p.png"},
    {{"ao", "{in}", "--rule", "lebedev:6", "-o", "{out}/a.glb"}, "--bits", "b.bin"},
    {{"ao", "--batch", "{list}", "--rule", "lebedev:6"}, "--out-dir", "baked"},
    {{"sky", "eval", "--input", "{csv}"}, "--output", "o.csv"},
    {{"sky", "render", "--altitude-km", "0", "--sun-elevation-deg", "10", "--size", "8x8"}, "-o", "r.png"},
    {{"sky", "train", "--samples", "100", "--epochs", "1", "--lm-iterations", "0"}, "-o", "w.json"},
    {{"sky", "train", "--samples", "100", "--epochs", "1", "--lm-iterations", "0", "-o", "{out}/w.json"},
     "--curve",
     "c.csv"},
    {{"sky", "train", "--samples", "100", "--epochs", "1", "--lm-iterations", "0", "-o", "{out}/w.json"},
     "--chart",
     "c.png"},
    {{"sky", "export", "{model}", "--format", "glsl"}, "-o", "s.glsl"},
    {{"sky", "preset", "earth"}, "-o", "e.json"},
    {{"sky", "error", "--model", "{model}", "--samples", "100", "--size", "8x8"}, "--views-dir", "views"},
    {{"sphere", "export", "lebedev:6"}, "-o", "r.csv"},
    {{"prt", "bake", "{in}", "--rule", "lebedev:6"}, "-o", "p.glb"},
    {{"sky", "sh", "--rule", "lebedev:50"}, "-o", "l.json"},
    {{"prt", "export", "--model", "{model}", "--glossy", "8"}, "-o", "p.glsl"},
};

} // namespace

TEST(CliContract, EveryOutputFlagChecksItsFolderBeforeWorkAndWritesNothingOnFailure) {
    for (const OutputFlag& f : kOutputFlags) {
        for (const char* bad_dir : {"/nonexistent-skybake-folder", "/proc"}) {
            const std::string out = skybake::test::temp_dir("contract-output");
            std::vector<std::string> args = expand(f.command, out);
            args.push_back(f.flag);
            args.push_back(std::string(bad_dir) + "/" + f.file);
            const CliResult r = run_cli(args, 60);
            expect_refused(r, 1, f.flag, describe(args));
            EXPECT_FALSE(fs::exists(std::string(bad_dir) + "/" + f.file));
            EXPECT_TRUE(files_in(out).empty()) << describe(args) << " left " << files_in(out).front();
        }
        // The command itself works: the same flag in a writable folder.
        const std::string out = skybake::test::temp_dir("contract-output-ok");
        std::vector<std::string> args = expand(f.command, out);
        args.push_back(f.flag);
        args.push_back(out + "/" + f.file);
        const CliResult ok = run_cli(args, 120);
        EXPECT_EQ(ok.exit_code, 0) << describe(args) << "\n" << ok.err;
        EXPECT_TRUE(fs::exists(out + "/" + f.file)) << describe(args);
    }
}

TEST(CliContract, AFailedCommandLeavesExistingOutputsUnchanged) {
    // The mesh would be written, but the preview cannot be: neither is.
    const std::string out = skybake::test::temp_dir("contract-unchanged");
    const std::string target = out + "/a.glb";
    std::ofstream(target) << "the user's file";
    for (const std::vector<std::string>& bad :
         {std::vector<std::string>{"--preview", "/nonexistent-skybake-folder/p.png"},
          std::vector<std::string>{"--bits", "/proc/b.bin"}, std::vector<std::string>{"--preview", out + "/p.jpg"},
          std::vector<std::string>{"--preview-azimuth", "nan", "--preview", out + "/p.png"}}) {
        std::vector<std::string> args = {"ao", inputs().mesh, "-o", target, "--rule", "lebedev:6"};
        args.insert(args.end(), bad.begin(), bad.end());
        const CliResult r = run_cli(args);
        EXPECT_NE(r.exit_code, 0) << describe(args);
        EXPECT_EQ(r.err_lines(), 1) << describe(args) << "\n" << r.err;
        std::ifstream in(target);
        std::stringstream s;
        s << in.rdbuf();
        EXPECT_EQ(s.str(), "the user's file") << describe(args);
        EXPECT_EQ(files_in(out).size(), 1u) << describe(args);
    }
}

TEST(CliContract, MessagesNameTheValueAndTheRangeReadably) {
    const std::string out = skybake::test::temp_dir("contract-messages");
    const CliResult a = run_cli({"mesh", "generate", "--triangles", "-5", "-o", out + "/m.glb"});
    expect_refused(a, 2, "-5 is out of range; expected a whole number from 20 to 50000000", "negative count");
    const CliResult b = run_cli({"ao", inputs().mesh, "-o", out + "/a.glb", "--max-distance", "1e30"});
    EXPECT_EQ(b.exit_code, 0) << b.err; // the largest distance allowed (it is stored as a float)
    const CliResult c =
        run_cli({"sky", "render", "--altitude-km", "0", "--sun-elevation-deg", "1000", "-o", out + "/r.png"});
    expect_refused(c, 2, "1000 is out of range; expected a number in [-90, 90] degrees", "elevation");
    EXPECT_LT(c.err.size(), 200u) << "no 300-digit numbers";
    const CliResult d = run_cli({"foo"});
    expect_refused(d, 2, "unknown command 'foo'", "unknown command");
    const CliResult e = run_cli({"sky", "frobnicate"});
    expect_refused(e, 2, "unknown command 'frobnicate' for 'skybake sky'", "unknown sub-command");
    const CliResult f = run_cli(
        {"sky", "train", "--samples", "1000", "--epochs", "1", "--lm-iterations", "0", "-q", "-o", out + "/w.json"});
    EXPECT_EQ(f.exit_code, 0) << "the default mini-batch shrinks to --samples: " << f.err;
    const CliResult g = run_cli(
        {"sky", "render", "--altitude-km", "0", "--sun-elevation-deg", "10", "--fov", "40", "-o", out + "/r.png"});
    expect_refused(g, 2, "--fov does not apply to --view fisheye", "a flag of another mode");
    const CliResult h = run_cli({"sky", "optical-length", "--paper-r", "5", "--density", "1", "--cos-zenith", "1"});
    expect_refused(h, 2, "--paper-r does not apply to preset earth", "a flag of another preset");
    const CliResult i = run_cli({"ao", inputs().mesh, "-o", out + "/a.glb", "--offset", "-1"});
    expect_refused(i, 2, "--offset", "a sentinel is not a value");
    const CliResult j = run_cli({"mesh", "convert", inputs().mesh, "-o", "/proc/x.glb"});
    expect_refused(j, 1, "/proc", "unwritable");
    EXPECT_EQ(j.err.find(".tmp-"), std::string::npos) << "no temporary file names: " << j.err;
}

TEST(CliContract, OpticalLengthMethodsAgreeOnHittingTheGround) {
    for (const char* cz : {"-1", "-0.5", "-0.1", "0", "0.3"})
        for (const char* density : {"1", "0.5"}) {
            bool hits[2] = {};
            for (int m = 0; m < 2; ++m) {
                const CliResult r = run_cli({"sky", "optical-length", "--density", density, "--cos-zenith", cz,
                                             "--method", m ? "exact" : "tables", "--json"});
                ASSERT_EQ(r.exit_code, 0) << r.err;
                hits[m] = r.out.find("\"hits_ground\": true") != std::string::npos;
            }
            EXPECT_EQ(hits[0], hits[1]) << "density " << density << ", cos zenith " << cz;
        }
}

TEST(CliContract, SignalsStopABakeAndAnImportCleanly) {
    const std::string dir = skybake::test::temp_dir("contract-signals");
    // A bake of a few seconds: 2CylinderEngine at 5810 directions.
    const std::string engine =
        skybake::test::assimp_models() + "/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb";
    // An import of a few seconds through the isolated Assimp reader: a large OBJ.
    const std::string obj = dir + "/big.obj";
    {
        std::ofstream f(obj);
        const int n = 700;
        for (int j = 0; j <= n; ++j)
            for (int i = 0; i <= n; ++i)
                f << "v " << i * 0.001 << ' ' << j * 0.001 << ' ' << ((i * 7 + j * 3) % 11) * 0.0001 << '\n';
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                const int a = j * (n + 1) + i + 1, b = a + 1, c = a + n + 1, d = c + 1;
                f << "f " << a << ' ' << b << ' ' << d << "\nf " << a << ' ' << d << ' ' << c << '\n';
            }
    }
    const std::string out = dir + "/outputs";
    fs::create_directories(out);
    for (int sig : {SIGTERM, SIGINT}) {
        for (const std::vector<std::string>& cmd :
             {std::vector<std::string>{"ao", engine, "-o", out + "/engine.glb", "--rule", "lebedev:5810"},
              std::vector<std::string>{"mesh", "convert", obj, "-o", out + "/big.glb"}}) {
            // The import: 0.2 s into the parse (it takes seconds). The bake:
            // 1.5 s in, after the start and the import, well before its end.
            const bool import = cmd[0] == "mesh";
            const CliResult r = skybake::test::run_cli_interrupted(cmd, import ? 0.2 : 1.5, sig, import);
            SCOPED_TRACE(describe(cmd) + (sig == SIGTERM ? " + SIGTERM" : " + SIGINT"));
            EXPECT_EQ(r.exit_code, 128 + sig) << r.err;
            EXPECT_EQ(r.err_lines(), 1) << r.err;
            EXPECT_NE(r.err.find("interrupted"), std::string::npos) << r.err;
            EXPECT_TRUE(files_in(out).empty()) << "left " << files_in(out).front();
        }
    }
    // The isolated reader died with its parent: no process still reads big.obj.
    usleep(200000);
    int readers = 0;
    for (const auto& e : fs::directory_iterator("/proc")) {
        std::ifstream cmdline(e.path() / "cmdline");
        std::string s((std::istreambuf_iterator<char>(cmdline)), std::istreambuf_iterator<char>());
        readers += s.find(obj) != std::string::npos;
    }
    EXPECT_EQ(readers, 0);
}
