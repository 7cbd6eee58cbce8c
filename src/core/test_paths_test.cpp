// The tests' folder of Assimp's sample models: $SKYBAKE_ASSIMP_MODELS when set
// (scripts/gpu-check.sh on a machine without the package), else the folder
// compiled in.
#include <cstdlib>
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include "core/test_paths.h"

namespace {

// Sets or unsets a variable for one scope and puts the old value back.
class ScopedEnv {
public:
    ScopedEnv(const char* name, const char* value) : name_(name) {
        if (const char* old = std::getenv(name))
            old_ = old;
        if (value)
            setenv(name, value, 1);
        else
            unsetenv(name);
    }
    ~ScopedEnv() {
        if (old_)
            setenv(name_, old_->c_str(), 1);
        else
            unsetenv(name_);
    }

private:
    const char* name_;
    std::optional<std::string> old_;
};

TEST(TestPaths, AssimpModelsFollowTheEnvironment) {
    {
        ScopedEnv e("SKYBAKE_ASSIMP_MODELS", nullptr);
        EXPECT_EQ(skybake::test::assimp_models(), SKYBAKE_ASSIMP_MODELS);
    }
    {
        ScopedEnv e("SKYBAKE_ASSIMP_MODELS", "");
        EXPECT_EQ(skybake::test::assimp_models(), SKYBAKE_ASSIMP_MODELS);
    }
    {
        ScopedEnv e("SKYBAKE_ASSIMP_MODELS", "/tmp/packed models");
        EXPECT_EQ(skybake::test::assimp_models(), "/tmp/packed models");
    }
}

} // namespace
