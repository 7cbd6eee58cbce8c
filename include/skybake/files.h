// skybake/files.h: all-or-nothing output files.
//
// Every file skybake writes is first written to a temporary file in the
// target's folder, then renamed over the target when complete, so a failure
// or a crash never leaves a half-written output behind.
#pragma once

#include <filesystem>
#include <functional>
#include <iosfwd>
#include <string>

namespace skybake {

// Calls write(tmp) with a fresh temporary path beside `target`, then renames
// tmp to target. If write throws, or leaves no file, the temporary is removed
// and the target is untouched. Throws skybake::Error on I/O failure.
void write_file_atomic(const std::filesystem::path& target,
                       const std::function<void(const std::filesystem::path& tmp)>& write);

// Same, for writers that produce a binary stream.
void write_stream_atomic(const std::filesystem::path& target,
                         const std::function<void(std::ostream& out)>& write);

// Reads a whole file; throws skybake::Error if it is missing, unreadable or
// larger than max_bytes.
std::string read_file(const std::filesystem::path& path, std::uint64_t max_bytes = std::uint64_t(1) << 32);

} // namespace skybake
