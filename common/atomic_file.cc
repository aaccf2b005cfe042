#include "common/atomic_file.h"

#include <unistd.h>

#include <cstdio>
#include <fstream>

#include "common/error.h"

namespace irbench {
namespace fs = std::filesystem;

void AtomicWriteWith(const fs::path& path, const std::function<void(const fs::path&)>& write) {
  const fs::path tmp = path.parent_path() /
                       ("." + path.filename().string() + ".tmp-" + std::to_string(getpid()));
  try {
    write(tmp);
  } catch (const std::exception& e) {
    std::remove(tmp.c_str());
    throw RuntimeError("cannot write " + path.string() + ": " + e.what());
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    std::remove(tmp.c_str());
    throw RuntimeError("cannot rename into " + path.string() + ": " + ec.message());
  }
}

void AtomicWriteFile(const fs::path& path, std::string_view bytes) {
  AtomicWriteWith(path, [&](const fs::path& tmp) {
    std::FILE* f = std::fopen(tmp.c_str(), "wb");
    if (f == nullptr) throw RuntimeError("cannot open " + tmp.string());
    const size_t written = std::fwrite(bytes.data(), 1, bytes.size(), f);
    if (std::fclose(f) != 0 || written != bytes.size()) throw RuntimeError("write failed (disk full?)");
  });
}

StagingDir::StagingDir(const fs::path& final_path, bool overwrite, const std::string& option)
    : final_path_(fs::absolute(final_path).lexically_normal()) {
  if (final_path_.filename().empty()) final_path_ = final_path_.parent_path();
  const fs::path parent = final_path_.parent_path();
  if (!fs::is_directory(parent)) {
    throw InputError("", option, "parent folder '" + parent.string() + "' does not exist");
  }
  if (fs::exists(final_path_) && !overwrite) {
    throw InputError("", option,
                     "'" + final_path_.string() + "' exists (pass --force to replace it)");
  }
  staging_path_ =
      parent / ("." + final_path_.filename().string() + ".partial-" + std::to_string(getpid()));
  std::error_code ec;
  fs::remove_all(staging_path_, ec);
  if (!fs::create_directory(staging_path_, ec) || ec) {
    throw RuntimeError("cannot create " + staging_path_.string() + ": " + ec.message());
  }
}

StagingDir::~StagingDir() {
  if (!committed_) {
    std::error_code ec;
    fs::remove_all(staging_path_, ec);
  }
}

void StagingDir::Commit() {
  std::error_code ec;
  fs::path old;
  if (fs::exists(final_path_)) {
    old = final_path_.parent_path() /
          ("." + final_path_.filename().string() + ".old-" + std::to_string(getpid()));
    fs::remove_all(old, ec);
    fs::rename(final_path_, old, ec);
    if (ec) throw RuntimeError("cannot move old " + final_path_.string() + " aside: " + ec.message());
  }
  fs::rename(staging_path_, final_path_, ec);
  if (ec) throw RuntimeError("cannot rename into " + final_path_.string() + ": " + ec.message());
  committed_ = true;
  if (!old.empty()) fs::remove_all(old, ec);
}

uint64_t Fnv1a64(std::string_view bytes, uint64_t seed) {
  uint64_t hash = seed;
  for (unsigned char c : bytes) {
    hash ^= c;
    hash *= 1099511628211ull;
  }
  return hash;
}

}  // namespace irbench
