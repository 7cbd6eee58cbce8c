// The CLI's contract: exit codes, one-line errors, --version and --help.
#include <gtest/gtest.h>

#include "cli_runner.h"

using skybake::test::run_cli;

TEST(Cli, VersionSaysWhetherCuda) {
    auto r = run_cli({"--version"});
    EXPECT_EQ(r.exit_code, 0);
    EXPECT_NE(r.out.find("skybake "), std::string::npos);
    EXPECT_TRUE(r.out.find("with CUDA") != std::string::npos || r.out.find("without CUDA") != std::string::npos);
}

TEST(Cli, HelpListsGroups) {
    auto r = run_cli({"--help"});
    EXPECT_EQ(r.exit_code, 0);
    EXPECT_NE(r.out.find("mesh"), std::string::npos);
}

TEST(Cli, UnknownFlagIsUsageErrorOnOneLine) {
    auto r = run_cli({"mesh", "info", "--no-such-flag", "x.obj"});
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_EQ(r.err_lines(), 1) << r.err;
    EXPECT_EQ(r.err.rfind("skybake: error: ", 0), 0u) << r.err;
}

TEST(Cli, MissingSubcommandIsUsageError) {
    auto r = run_cli({});
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_EQ(r.err_lines(), 1) << r.err;
}
