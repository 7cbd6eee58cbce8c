// `--device cuda` on the sky commands: without a GPU, one line and exit 1 with
// no output; with one, the same answers as the CPU.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "cli_runner.h"
#include "skybake/core.h"
#include "core/gpu_test.h"

using skybake::test::run_cli;
using skybake::test::temp_dir;
namespace fs = std::filesystem;

namespace {
std::string write_input(const std::string& dir) {
    const std::string p = dir + "/in.csv";
    std::ofstream(p) << "cos_view_zenith,cos_view_sun,cos_sun_zenith,density\n1,0.8,0.8,1\n0.1,0.95,0.05,1\n"
                        "0.5,-0.2,0.3,0.5\n";
    return p;
}
std::vector<double> read_numbers(const std::string& path) {
    std::ifstream in(path);
    std::string line;
    std::getline(in, line); // header
    std::vector<double> v;
    while (std::getline(in, line)) {
        std::stringstream ss(line);
        std::string cell;
        while (std::getline(ss, cell, ','))
            v.push_back(std::stod(cell));
    }
    return v;
}
} // namespace

TEST(GpuSkyCli, NoDeviceIsOneLineAndNoOutput) {
    if (skybake::cuda_device_count() > 0)
        GTEST_SKIP() << "a CUDA device is present";
    const std::string dir = temp_dir("gpu-cli-none");
    const std::string in = write_input(dir);
    const std::vector<std::vector<std::string>> commands = {
        {"sky", "eval", "--preset", "earth", "--input", in, "--output", dir + "/out.csv", "--device", "cuda"},
        {"sky", "render", "--preset", "earth", "--altitude-km", "0", "--sun-elevation-deg", "30", "--size", "32x32",
         "-o", dir + "/sky.png", "--device", "cuda"},
        {"sky", "train", "--preset", "earth", "--samples", "2000", "-o", dir + "/w.json", "--device", "cuda"}};
    for (const auto& args : commands) {
        const auto r = run_cli(args);
        EXPECT_EQ(r.exit_code, 1) << r.err;
        EXPECT_EQ(r.err_lines(), 1) << r.err;
        EXPECT_NE(r.err.find("--device"), std::string::npos) << r.err;
    }
    // Only the input is left in the folder.
    EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
}

TEST(GpuSkyCli, UnknownDeviceIsAnError) {
    const std::string dir = temp_dir("gpu-cli-bad");
    const auto r = run_cli({"sky", "eval", "--preset", "earth", "--input", write_input(dir), "--output",
                            dir + "/out.csv", "--device", "tpu"});
    EXPECT_EQ(r.exit_code, 2); // a bad flag value: a usage error
    EXPECT_EQ(r.err_lines(), 1) << r.err;
}

TEST(GpuSkyCli, CudaAgreesWithCpu) {
    SKYBAKE_SKIP_WITHOUT_GPU();
    const std::string dir = temp_dir("gpu-cli-agree");
    const std::string in = write_input(dir);
    ASSERT_EQ(run_cli({"sky", "eval", "--preset", "earth", "--input", in, "--output", dir + "/cpu.csv"}).exit_code, 0);
    ASSERT_EQ(run_cli({"sky", "eval", "--preset", "earth", "--input", in, "--output", dir + "/gpu.csv", "--device",
                       "cuda"})
                  .exit_code,
              0);
    const auto a = read_numbers(dir + "/cpu.csv"), b = read_numbers(dir + "/gpu.csv");
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i)
        EXPECT_NEAR(b[i], a[i], 1e-4 * std::abs(a[i]) + 1e-9);
}
