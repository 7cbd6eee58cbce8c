// Finding the image a model file names, when the model was written on another
// machine: FBX, OBJ and DAE files keep the path the artist's tool saw
// ("D:\projects\car\tex\paint.jpg", "..\tex\paint.jpg", "/home/me/paint.png").
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace skybake::io {

// The file `written` names, looked for in this order:
//   1. as written, with '\' read as '/' (relative paths from model_dir);
//   2. its trailing folders and file name, longest first, under model_dir and
//      then under model_dir's parent: "D:\a\models\OBJ\wood.jpg" next to
//      models/FBX/spider.fbx is found as models/OBJ/wood.jpg.
// nullopt when none exists (or model_dir is empty and the path is relative).
std::optional<std::filesystem::path> find_texture(std::string_view written, const std::filesystem::path& model_dir);

// "My%20File.png" -> "My File.png" (RFC 3986 percent-encoding, as glTF URIs use).
std::string percent_decode(std::string_view uri);

} // namespace skybake::io
