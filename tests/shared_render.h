#pragma once
// One render shared by the tests of one test binary. CTest runs each GoogleTest
// test in its own process (gtest_discover_tests), so a suite set-up that
// renders runs once per test: SharedRender renders the first time, under a
// lock, into <build>/test-renders/<stamp of this test binary>/<name>, and every
// test (the first included) gets its own copy at `options.out` to read and
// write. The stamp (the binary's modification time) keeps a render made by an
// older build from being used; CTest also clears <build>/test-renders before
// the first test that uses it and after the last (the fixture "test_renders",
// irbench_test(... SHARED_RENDERS) in cmake/irbench_helpers.cmake), so data
// files changed between two ctest runs are rendered again.

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "sim/sequence/render_job.h"

namespace irbench::testing {

inline std::filesystem::path SharedRenderRoot() {
  namespace fs = std::filesystem;
  const fs::path exe = fs::read_symlink("/proc/self/exe");
  const auto stamp = fs::last_write_time(exe).time_since_epoch();
  return fs::path(IRBENCH_BINARY_DIR) / "test-renders" /
         (exe.filename().string() + "-" +
          std::to_string(std::chrono::duration_cast<std::chrono::nanoseconds>(stamp).count()));
}

// Renders `options` once per test binary under `name` (one name per set of
// options) and copies the sequence to `options.out`, which it returns.
inline std::filesystem::path SharedRender(const std::string& name, RenderJobOptions options) {
  namespace fs = std::filesystem;
  const fs::path root = SharedRenderRoot();
  fs::create_directories(root);
  const fs::path lock_path = root / (name + ".lock");
  const int lock = ::open(lock_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (lock < 0 || ::flock(lock, LOCK_EX) != 0) throw std::runtime_error("cannot lock " + lock_path.string());
  const fs::path shared = root / name;
  const fs::path out = options.out;
  try {
    // RunRenderJob renames a finished sequence into place: present is whole.
    if (!fs::exists(shared)) {
      options.out = shared;
      RunRenderJob(options);
    }
  } catch (...) {
    ::close(lock);  // releases the lock
    throw;
  }
  ::close(lock);
  fs::remove_all(out);
  fs::create_directories(out.parent_path());
  fs::copy(shared, out, fs::copy_options::recursive);
  return out;
}

}  // namespace irbench::testing
