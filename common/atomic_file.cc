#include "common/atomic_file.h"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstdio>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>

#include "common/error.h"
#include "common/logging.h"
#include "common/paths.h"

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

namespace {

// `p` absolute, normal, links resolved where they exist, no trailing slash.
fs::path Resolved(const fs::path& p) {
  std::error_code ec;
  fs::path r = fs::weakly_canonical(fs::absolute(p), ec);
  if (ec) r = fs::absolute(p).lexically_normal();
  if (r.filename().empty() && r.has_parent_path()) r = r.parent_path();
  return r;
}

// Whether `child` is `parent` or lies inside it (both Resolved).
bool Within(const fs::path& child, const fs::path& parent) {
  const fs::path rel = child.lexically_relative(parent);
  return !rel.empty() && *rel.begin() != "..";
}

// `.<name>.partial-` for the final path `final_path`.
std::string StagingPrefix(const fs::path& final_path) {
  return "." + final_path.filename().string() + ".partial-";
}

// The pid in `name` when it is exactly `prefix` followed by a positive decimal number.
std::optional<pid_t> StagingPid(const std::string& name, const std::string& prefix) {
  if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) return std::nullopt;
  long long pid = 0;
  const char* first = name.data() + prefix.size();
  const char* last = name.data() + name.size();
  const auto [ptr, ec] = std::from_chars(first, last, pid);
  if (ec != std::errc() || ptr != last || *first == '0' || pid <= 0 || pid > std::numeric_limits<pid_t>::max()) {
    return std::nullopt;
  }
  return static_cast<pid_t>(pid);
}

// Whether no process `pid` exists (a process of another user does).
bool ProcessGone(pid_t pid) { return kill(pid, 0) != 0 && errno == ESRCH; }

std::string MarkerLine(const std::string& command) {
  return nlohmann::json{{"format", "irbench.output/1"}, {"tool_version", ToolVersion()}, {"command", command}}
             .dump() +
         "\n";
}

}  // namespace

bool IsIrbenchOutput(const fs::path& folder) {
  std::error_code ec;
  return fs::is_directory(fs::symlink_status(folder, ec)) && fs::is_regular_file(folder / kOutputMarker, ec);
}

void CheckOutputApart(const fs::path& out, const std::vector<fs::path>& inputs, const std::string& option) {
  const fs::path out_path = Resolved(out);
  for (const fs::path& input : inputs) {
    if (input.empty()) continue;
    const fs::path in_path = Resolved(input);
    if (out_path == in_path) {
      throw InputError("", option, "'" + out.string() + "' is an input of this command; it would be replaced");
    }
    if (Within(in_path, out_path)) {
      throw InputError("", option, "'" + out.string() + "' contains the input '" + in_path.string() +
                                       "'; it would be replaced");
    }
    if (Within(out_path, in_path)) {
      throw InputError("", option, "'" + out.string() + "' lies inside the input '" + in_path.string() + "'");
    }
  }
}

void CheckOutputReplaceable(const fs::path& out, bool overwrite, const std::string& option) {
  fs::path given = fs::absolute(out).lexically_normal();
  if (given.filename().empty()) given = given.parent_path();
  if (!fs::is_directory(given.parent_path())) {
    throw InputError("", option, "parent folder '" + given.parent_path().string() + "' does not exist");
  }
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(given, ec))) return;
  if (!overwrite) throw InputError("", option, "'" + out.string() + "' exists (pass --force to replace it)");
  if (!IsIrbenchOutput(given)) {
    throw InputError("", option, "'" + out.string() + "' was not written by irbench (no " + kOutputMarker +
                                     " in it) and will not be replaced");
  }
}

std::vector<fs::path> StaleStagingDirs(const fs::path& final_path) {
  const fs::path final_abs = Resolved(final_path);
  const std::string prefix = StagingPrefix(final_abs);
  std::vector<std::pair<fs::file_time_type, fs::path>> found;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(final_abs.parent_path(), ec)) {
    const auto pid = StagingPid(entry.path().filename().string(), prefix);
    if (!pid || *pid == getpid() || !entry.is_directory(ec) || entry.is_symlink(ec) || !ProcessGone(*pid)) continue;
    found.emplace_back(fs::last_write_time(entry.path(), ec), entry.path());
  }
  std::sort(found.begin(), found.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<fs::path> out;
  for (const auto& [time, path] : found) out.push_back(path);
  return out;
}

StagingDir::StagingDir(const fs::path& final_path,
                       bool overwrite,
                       const std::string& option,
                       std::string command,
                       Stale stale)
    : final_path_(fs::absolute(final_path).lexically_normal()),
      option_(option),
      command_(std::move(command)),
      overwrite_(overwrite) {
  if (final_path_.filename().empty()) final_path_ = final_path_.parent_path();
  CheckOutputReplaceable(final_path_, overwrite, option);
  const fs::path parent = final_path_.parent_path();
  staging_path_ = parent / (StagingPrefix(final_path_) + std::to_string(getpid()));
  std::error_code ec;
  fs::remove_all(staging_path_, ec);
  for (const fs::path& old : StaleStagingDirs(final_path_)) {
    if (stale == Stale::kAdopt && !adopted_) {
      fs::rename(old, staging_path_, ec);
      adopted_ = !ec;
      if (adopted_) {
        Log().info("resuming from {} (its process is gone)", old.string());
        continue;
      }
    }
    fs::remove_all(old, ec);
    Log().info("removed {}: an unfinished output of a process that is gone", old.string());
  }
  if (adopted_) return;
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

void StagingDir::Clear() {
  std::error_code ec;
  fs::remove_all(staging_path_, ec);
  if (!fs::create_directory(staging_path_, ec) || ec) {
    throw RuntimeError("cannot create " + staging_path_.string() + ": " + ec.message());
  }
  adopted_ = false;
}

void StagingDir::Commit() {
  AtomicWriteFile(staging_path_ / kOutputMarker, MarkerLine(command_));
  std::error_code ec;
  fs::path old;
  if (fs::exists(fs::symlink_status(final_path_, ec))) {
    CheckOutputReplaceable(final_path_, overwrite_, option_);
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
