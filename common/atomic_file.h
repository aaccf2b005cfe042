#pragma once
// Writing outputs so that nothing half-written is ever visible: files go to a
// temporary name beside their destination and are renamed into place; a whole
// output folder is built under a hidden staging name and renamed when complete.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>

namespace irbench {

// Writes `bytes` to `path` via a temporary file in the same folder and rename().
// Throws RuntimeError on I/O failure (the temporary is removed).
void AtomicWriteFile(const std::filesystem::path& path, std::string_view bytes);

// The same for writers that need a file name (image libraries): `write` fills
// the temporary path it is given; on any exception the temporary is removed
// and a RuntimeError naming `path` is thrown.
void AtomicWriteWith(const std::filesystem::path& path,
                     const std::function<void(const std::filesystem::path& temporary)>& write);

// A folder that becomes `final_path` only on Commit(). Until then it lives at
// `<parent>/.<name>.partial-<pid>`; the destructor removes it if not committed,
// so an error or an interrupt leaves nothing behind.
class StagingDir {
 public:
  // Checks that the parent exists (InputError on `option` otherwise) and that
  // `final_path` does not exist unless `overwrite`.
  StagingDir(const std::filesystem::path& final_path, bool overwrite, const std::string& option);
  ~StagingDir();
  StagingDir(const StagingDir&) = delete;
  StagingDir& operator=(const StagingDir&) = delete;

  const std::filesystem::path& path() const { return staging_path_; }
  const std::filesystem::path& final_path() const { return final_path_; }
  // Renames the staging folder to the final path (replacing an old one).
  void Commit();

 private:
  std::filesystem::path final_path_;
  std::filesystem::path staging_path_;
  bool committed_ = false;
};

// SHA-256-free content hash for caching and tests: 64-bit FNV-1a.
uint64_t Fnv1a64(std::string_view bytes, uint64_t seed = 1469598103934665603ull);

}  // namespace irbench
