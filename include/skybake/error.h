// skybake/error.h: the one error type raised at the library's boundaries.
//
// Inside the library, contracts are asserted. Where data comes from outside
// (files, flags, CUDA, Embree), a failure throws skybake::Error. Its message
// says what was wrong and, where useful, what to do; `where` names the place
// (a file path, "line 12 of sky.csv", a flag such as "--triangles").
// The CLI prints it as one line:  skybake: error: <message> (<where>)
#pragma once

#include <stdexcept>
#include <string>

namespace skybake {

class Error : public std::runtime_error {
public:
    explicit Error(std::string message, std::string where = {});

    // What went wrong, without the location.
    const std::string& message() const noexcept { return message_; }
    // Where it went wrong; may be empty.
    const std::string& where() const noexcept { return where_; }

private:
    std::string message_;
    std::string where_;
};

// Formats "message (where)", or just "message" when where is empty, on a single
// line: newlines and other control characters are replaced by spaces.
std::string format_error_line(const std::string& message, const std::string& where);

} // namespace skybake
