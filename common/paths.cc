#include "common/paths.h"

#include <algorithm>
#include <cstdlib>
#include <vector>

#include "common/error.h"

namespace irbench {
namespace fs = std::filesystem;

fs::path InstalledDataRoot() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return {};
  const fs::path share = (exe.parent_path() / ".." / "share" / "irbench").lexically_normal();
  return fs::is_directory(share / "scenes", ec) ? share : fs::path();
}

fs::path DataRoot() {
  if (const char* env = std::getenv("IRBENCH_DATA_DIR"); env != nullptr && *env != '\0') {
    return fs::path(env);
  }
  if (fs::path installed = InstalledDataRoot(); !installed.empty()) return installed;
  return fs::path(IRBENCH_SOURCE_DIR);
}

fs::path OutputRoot() {
  const char* env = std::getenv("IRBENCH_DATA_DIR");
  if ((env == nullptr || *env == '\0') && !InstalledDataRoot().empty()) return fs::current_path();
  return DataRoot();
}

fs::path ResolveDataFile(const std::string& kind,
                         const std::string& name_or_path,
                         const std::string& option) {
  if (name_or_path.empty()) throw InputError("", option, "empty name");
  const fs::path as_path(name_or_path);
  const bool looks_like_path = name_or_path.find('/') != std::string::npos ||
                               as_path.has_extension();
  if (looks_like_path) {
    if (!fs::is_regular_file(as_path)) {
      throw InputError(name_or_path, option, "no such file");
    }
    return as_path;
  }
  const fs::path folder = DataRoot() / kind;
  const fs::path candidate = folder / (name_or_path + ".json");
  if (fs::is_regular_file(candidate)) return candidate;
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    if (entry.path().extension() == ".json") names.push_back(entry.path().stem().string());
  }
  std::sort(names.begin(), names.end());
  std::string available;
  for (const std::string& n : names) available += (available.empty() ? "" : ", ") + n;
  throw InputError("", option,
                   "unknown " + kind.substr(0, kind.size() - 1) + " '" + name_or_path +
                       "' (available in " + folder.string() + ": " + available + ")");
}

std::string ToolVersion() { return IRBENCH_VERSION; }

fs::path UserCacheDir() {
  if (const char* env = std::getenv("IRBENCH_CACHE_DIR"); env != nullptr) {
    const std::string dir(env);
    return dir.empty() || dir == "off" ? fs::path() : fs::path(dir);
  }
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg != nullptr && *xdg == '/') return fs::path(xdg) / "irbench";
  if (const char* home = std::getenv("HOME"); home != nullptr && *home == '/') {
    return fs::path(home) / ".cache" / "irbench";
  }
  return {};
}

}  // namespace irbench
