#include "skybake/error.h"

namespace skybake {

std::string format_error_line(const std::string& message, const std::string& where) {
    std::string line = where.empty() ? message : message + " (" + where + ")";
    for (char& c : line)
        if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
            c = ' ';
    return line;
}

Error::Error(std::string message, std::string where)
    : std::runtime_error(format_error_line(message, where)),
      message_(std::move(message)),
      where_(std::move(where)) {}

} // namespace skybake
