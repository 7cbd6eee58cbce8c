#pragma once

#include <cstddef>
#include <string>

namespace skybake::io {

// Checks the JSON of a .gltf (binary = false) or .glb file. Returns the
// glTF major version (1 or 2). For version 2, the types of every core member
// are checked; throws skybake::Error naming the first malformed member.
int check_gltf(const void* data, std::size_t size, bool binary, const std::string& where);

} // namespace skybake::io
