#pragma once
// Resolving names (`theater`, `theater4`, `p1`) to data files in the project's
// folders; a path works anywhere a name does.

#include <filesystem>
#include <string>

namespace irbench {

// The folder that holds scenes/, rigs/, avatars/, motions/: $IRBENCH_DATA_DIR if
// set, else the source tree this binary was built from.
std::filesystem::path DataRoot();

// `kind` is a folder name ("scenes"); `name_or_path` is a name or a file path.
// Throws InputError naming `option` and the names available when nothing matches.
std::filesystem::path ResolveDataFile(const std::string& kind,
                                      const std::string& name_or_path,
                                      const std::string& option);

std::string ToolVersion();

}  // namespace irbench
