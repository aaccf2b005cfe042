#pragma once
// Writing outputs so that nothing half-written is ever visible: files go to a
// temporary name beside their destination and are renamed into place; a whole
// output folder is built under a hidden staging name and renamed when complete.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace irbench {

// Writes `bytes` to `path` via a temporary file in the same folder and rename().
// Throws RuntimeError on I/O failure (the temporary is removed).
void AtomicWriteFile(const std::filesystem::path& path, std::string_view bytes);

// The same for writers that need a file name (image libraries): `write` fills
// the temporary path it is given; on any exception the temporary is removed
// and a RuntimeError naming `path` is thrown.
void AtomicWriteWith(const std::filesystem::path& path,
                     const std::function<void(const std::filesystem::path& temporary)>& write);

// Every output folder irbench writes carries this file: one line of JSON,
// {"format": "irbench.output/1", "tool_version": ..., "command": ...}. --force
// replaces an existing path only when it is a folder carrying it, so that
// nothing irbench did not write is ever deleted.
inline constexpr char kOutputMarker[] = ".irbench-output";

// Whether `folder` is a folder (not a link to one) carrying kOutputMarker.
bool IsIrbenchOutput(const std::filesystem::path& folder);

// Refuses (InputError on `option`) an output path that equals, contains or
// lies inside any of `inputs`: the files and folders the command reads (empty
// paths are skipped). Paths are compared with links resolved.
void CheckOutputApart(const std::filesystem::path& out,
                      const std::vector<std::filesystem::path>& inputs,
                      const std::string& option);

// Refuses (InputError on `option`) an output the command may not write: its
// parent folder missing; existing without `overwrite`; existing but not a
// folder irbench wrote (no kOutputMarker). Cheap, for a check before slow
// work; StagingDir checks it again.
void CheckOutputReplaceable(const std::filesystem::path& out, bool overwrite, const std::string& option);

// A folder that becomes `final_path` only on Commit(). Until then it lives at
// `<parent>/.<name>.partial-<pid>`; the destructor removes it if not committed,
// so an error or an interrupt leaves nothing behind. A process killed outright
// (SIGKILL, power loss) leaves its staging folder: the next StagingDir for the
// same `final_path` removes those of processes no longer running, or adopts
// the newest to resume from (Stale::kAdopt).
class StagingDir {
 public:
  enum class Stale { kRemove, kAdopt };

  // Checks CheckOutputReplaceable(final_path, overwrite, option); `command`
  // ("render", "track", ...) goes into the marker Commit() writes.
  StagingDir(const std::filesystem::path& final_path,
             bool overwrite,
             const std::string& option,
             std::string command = "output",
             Stale stale = Stale::kRemove);
  ~StagingDir();
  StagingDir(const StagingDir&) = delete;
  StagingDir& operator=(const StagingDir&) = delete;

  const std::filesystem::path& path() const { return staging_path_; }
  const std::filesystem::path& final_path() const { return final_path_; }
  // Whether path() is a dead process's staging folder, adopted with its
  // contents (Stale::kAdopt and one was found).
  bool adopted() const { return adopted_; }
  // Empties the staging folder (an adopted one that cannot be resumed).
  void Clear();
  // Writes the marker and renames the staging folder to the final path
  // (replacing an old one, checked again to be irbench's).
  void Commit();

 private:
  std::filesystem::path final_path_;
  std::filesystem::path staging_path_;
  std::string option_;
  std::string command_;
  bool overwrite_ = false;
  bool committed_ = false;
  bool adopted_ = false;
};

// The staging folders `.<name>.partial-<pid>` of `final_path` whose process
// is no longer running (kill(pid, 0) fails with ESRCH), newest first.
std::vector<std::filesystem::path> StaleStagingDirs(const std::filesystem::path& final_path);

// SHA-256-free content hash for caching and tests: 64-bit FNV-1a.
uint64_t Fnv1a64(std::string_view bytes, uint64_t seed = 1469598103934665603ull);

}  // namespace irbench
