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
#include <utility>
#include <vector>

namespace skybake {

// Calls write(tmp) with a fresh temporary path beside `target`, then renames
// tmp to target. If write throws, or leaves no file, the temporary is removed
// and the target is untouched. Throws skybake::Error on I/O failure.
void write_file_atomic(const std::filesystem::path& target,
                       const std::function<void(const std::filesystem::path& tmp)>& write);

// Same, for writers that produce a binary stream.
void write_stream_atomic(const std::filesystem::path& target,
                         const std::function<void(std::ostream& out)>& write);

// Several output files committed as one: each is written under a staging
// name beside its target (same folder, same extension, so any writer that
// picks its format by extension works), and commit() renames them all into
// place once every one is complete. A set destroyed before commit() removes
// what it staged, so a failure in the third file leaves the first two
// targets untouched.
class OutputSet {
public:
    OutputSet() = default;
    OutputSet(const OutputSet&) = delete;
    OutputSet& operator=(const OutputSet&) = delete;
    ~OutputSet();

    // The path to write `target`'s contents to. Throws skybake::Error if the
    // target's folder does not exist or the target is a folder.
    std::filesystem::path stage(const std::filesystem::path& target);
    // Renames every staged file onto its target. Throws skybake::Error naming
    // the target if one cannot be renamed (the others are still committed).
    void commit();

private:
    std::vector<std::pair<std::filesystem::path, std::filesystem::path>> staged_; // staging path, target
};

// Reads a whole file; throws skybake::Error if it is missing, unreadable or
// larger than max_bytes.
std::string read_file(const std::filesystem::path& path, std::uint64_t max_bytes = std::uint64_t(1) << 32);

// The folder of skybake's on-disk caches (multiple-scattering tables,
// spherical designs): $SKYBAKE_CACHE_DIR when set and not empty ("off",
// "none" or "0": no cache, nothing read or written), else
// $XDG_CACHE_HOME/skybake (an absolute XDG_CACHE_HOME; the XDG spec ignores a
// relative one), else $HOME/.cache/skybake. Empty when disabled, or without
// HOME. Read again at each call. The folder is created on the first write.
std::filesystem::path cache_dir();

} // namespace skybake
