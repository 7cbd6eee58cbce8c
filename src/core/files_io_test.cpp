// All-or-nothing output files (skybake/files.h): a writer that fails half way
// leaves the old target as it was and no temporary file beside it.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <gtest/gtest.h>
#include <unistd.h>

#include "skybake/error.h"
#include "skybake/files.h"

using namespace skybake;
namespace fs = std::filesystem;

namespace {

fs::path fresh_dir(const std::string& name) {
    const fs::path dir = fs::temp_directory_path() / ("skybake-files-test-" + std::to_string(::getpid())) / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

std::size_t entries(const fs::path& dir) {
    std::size_t n = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir))
        ++n;
    return n;
}

} // namespace

TEST(WriteFileAtomic, AWriterThatFailsHalfWayLeavesTheOldFileAndNoTemporary) {
    const fs::path dir = fresh_dir("half");
    const fs::path target = dir / "out.bin";
    std::ofstream(target, std::ios::binary) << "the old contents";
    fs::path seen_tmp;
    EXPECT_THROW(write_file_atomic(target,
                                   [&](const fs::path& tmp) {
                                       seen_tmp = tmp;
                                       std::ofstream out(tmp, std::ios::binary);
                                       out << "half of the new fi";
                                       out.flush();
                                       ASSERT_TRUE(fs::exists(tmp)); // the temporary really exists here
                                       throw Error("disk on fire");
                                   }),
                 Error);
    EXPECT_EQ(seen_tmp.parent_path(), dir);
    EXPECT_NE(seen_tmp, target);
    EXPECT_FALSE(fs::exists(seen_tmp));
    EXPECT_EQ(slurp(target), "the old contents");
    EXPECT_EQ(entries(dir), 1u);
}

TEST(WriteFileAtomic, AnyExceptionTypeIsCleanedUp) {
    const fs::path dir = fresh_dir("any");
    EXPECT_THROW(write_file_atomic(dir / "x.bin",
                                   [](const fs::path& tmp) {
                                       std::ofstream(tmp) << "partial";
                                       throw std::runtime_error("not a skybake error");
                                   }),
                 std::runtime_error);
    EXPECT_EQ(entries(dir), 0u);
}

TEST(WriteFileAtomic, AStreamWriterThatFailsHalfWayLeavesTheOldFile) {
    const fs::path dir = fresh_dir("stream");
    const fs::path target = dir / "out.txt";
    std::ofstream(target) << "old";
    EXPECT_THROW(write_stream_atomic(target,
                                     [](std::ostream& out) {
                                         out << std::string(1 << 20, 'x'); // past any stream buffer
                                         throw Error("stopped");
                                     }),
                 Error);
    EXPECT_EQ(slurp(target), "old");
    EXPECT_EQ(entries(dir), 1u);
}

TEST(WriteFileAtomic, SuccessReplacesTheTargetWhole) {
    const fs::path dir = fresh_dir("ok");
    const fs::path target = dir / "out.txt";
    std::ofstream(target) << "old and longer than the new one";
    write_stream_atomic(target, [](std::ostream& out) { out << "new"; });
    EXPECT_EQ(slurp(target), "new");
    EXPECT_EQ(entries(dir), 1u);
}

TEST(WriteFileAtomic, AWriterThatWritesNothingIsAnError) {
    const fs::path dir = fresh_dir("nothing");
    const fs::path target = dir / "out.txt";
    std::ofstream(target) << "old";
    EXPECT_THROW(write_file_atomic(target, [](const fs::path&) {}), Error);
    EXPECT_EQ(slurp(target), "old");
    EXPECT_EQ(entries(dir), 1u);
}

TEST(WriteFileAtomic, BadTargetsFailBeforeTheWriterRuns) {
    const fs::path dir = fresh_dir("targets");
    bool called = false;
    const auto writer = [&](const fs::path& tmp) {
        called = true;
        std::ofstream(tmp) << "x";
    };
    EXPECT_THROW(write_file_atomic(dir / "missing" / "x.txt", writer), Error);
    EXPECT_THROW(write_file_atomic(dir, writer), Error); // a folder
    EXPECT_THROW(write_file_atomic(fs::path(), writer), Error);
    EXPECT_FALSE(called);
    EXPECT_EQ(entries(dir), 0u);
}

TEST(ReadFile, MaxBytesIsEnforcedAtTheBoundary) {
    const fs::path dir = fresh_dir("read");
    const fs::path p = dir / "ten.bin";
    std::ofstream(p, std::ios::binary) << "0123456789";
    EXPECT_EQ(read_file(p, 10), "0123456789"); // exactly the limit: allowed
    try {
        read_file(p, 9);
        FAIL() << "read past max_bytes";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("10 bytes"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("9 bytes"), std::string::npos) << e.what();
        EXPECT_EQ(e.where(), p.string());
    }
    EXPECT_EQ(read_file(p), "0123456789");
    EXPECT_THROW(read_file(dir / "missing.bin"), Error);
    EXPECT_THROW(read_file(dir), Error);
    std::ofstream(dir / "empty.bin");
    EXPECT_EQ(read_file(dir / "empty.bin", 0), "");
}
