#pragma once
// `irbench avatar list | info | export`.

#include <filesystem>
#include <string>

namespace irbench {

// The avatars in avatars/, one per line: name, kind, height, description.
std::string AvatarListText();

// An avatar's measures: height, triangles, vertices, whether it is closed.
std::string AvatarInfoText(const std::string& name_or_path);

// Writes the avatar as binary glTF; refuses an existing file unless `overwrite`.
std::filesystem::path ExportAvatar(const std::string& name_or_path, const std::filesystem::path& out,
                                   bool overwrite);

}  // namespace irbench
