#include "fuzz/fuzz_input.h"

#include <unistd.h>

#include <fstream>
#include <system_error>

#include "common/logging.h"

namespace irbench::fuzz {
namespace fs = std::filesystem;

void QuietLogging() { Log().set_level(spdlog::level::off); }

std::vector<std::string> SplitParts(const uint8_t* data, size_t size, size_t parts) {
  std::string_view rest(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> out;
  while (out.size() + 1 < parts) {
    const size_t at = rest.find(kPartSeparator);
    if (at == std::string_view::npos) break;
    out.emplace_back(rest.substr(0, at));
    rest.remove_prefix(at + kPartSeparator.size());
  }
  out.emplace_back(rest);
  out.resize(parts);
  return out;
}

namespace {

// Removes the scratch folder when the process exits normally (libFuzzer's
// -max_total_time and -runs end with exit()); a crash leaves it for a look.
struct Scratch {
  fs::path dir = fs::temp_directory_path() / ("irbench-fuzz-" + std::to_string(getpid()));
  Scratch() { fs::create_directories(dir); }
  ~Scratch() {
    std::error_code ignored;
    fs::remove_all(dir, ignored);
  }
};

}  // namespace

const fs::path& ScratchDir() {
  static const Scratch scratch;
  return scratch.dir;
}

fs::path WriteScratchFile(const std::string& name, std::string_view bytes) {
  const fs::path path = ScratchDir() / name;
  fs::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return path;
}

}  // namespace irbench::fuzz
