#pragma once
// Resolving names (`theater`, `theater4`, `p1`) to data files in the project's
// folders; a path works anywhere a name does.

#include <filesystem>
#include <string>

namespace irbench {

// The folder that holds scenes/, rigs/, avatars/, motions/ (and ci/suites/,
// ci/baselines/, tracker/models/): $IRBENCH_DATA_DIR if set; else, for an
// installed program, <prefix>/share/irbench beside its bin/ (cmake --install,
// the .deb); else the source tree this binary was built from.
std::filesystem::path DataRoot();

// Where default outputs go (renders/<name>, renders/demo, renders/cache): the
// data root, unless that is an installed, shared folder; then the current
// folder.
std::filesystem::path OutputRoot();

// <exe>/../share/irbench when it holds scenes/ (an installed program); empty
// otherwise.
std::filesystem::path InstalledDataRoot();

// `kind` is a folder name ("scenes"); `name_or_path` is a name or a file path.
// Throws InputError naming `option` and the names available when nothing matches.
std::filesystem::path ResolveDataFile(const std::string& kind,
                                      const std::string& name_or_path,
                                      const std::string& option);

std::string ToolVersion();

// The folder for caches of derived data that any run may rebuild (the bounce
// light's volumes, docs/sensor.md): $IRBENCH_CACHE_DIR when set (empty or
// "off": no cache), else $XDG_CACHE_HOME/irbench, else $HOME/.cache/irbench.
// Empty when there is none. Not created here.
std::filesystem::path UserCacheDir();

}  // namespace irbench
