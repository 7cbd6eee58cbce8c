// For tests: folders outside the source tree that tests read.
#pragma once

#include <cstdlib>
#include <string>

namespace skybake::test {

// Assimp's sample models (Debian's assimp-testmodels): $SKYBAKE_ASSIMP_MODELS
// when it is set and not empty (scripts/gpu-check.sh packs the few the GPU and
// GL tests read for a machine without the package), else the folder compiled
// in as SKYBAKE_ASSIMP_MODELS (/usr/share/assimp/models).
inline std::string assimp_models() {
    const char* v = std::getenv("SKYBAKE_ASSIMP_MODELS");
    return v && *v ? std::string(v) : std::string(SKYBAKE_ASSIMP_MODELS);
}

} // namespace skybake::test
