#include "common/progress.h"

#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstdio>

#include "common/logging.h"

namespace irbench {

namespace {
std::atomic<int> quiet_scopes{0};
}  // namespace

bool StderrIsTerminal() { return ::isatty(STDERR_FILENO) == 1; }

QuietProgress::QuietProgress() { ++quiet_scopes; }
QuietProgress::~QuietProgress() { --quiet_scopes; }

Progress::Progress(std::string what, std::string unit, int total)
    : Progress(std::move(what), std::move(unit), total, StderrIsTerminal(), 5.0) {}

Progress::Progress(std::string what, std::string unit, int total, bool terminal, double plain_period_s)
    : what_(std::move(what)),
      unit_(std::move(unit)),
      total_(total),
      terminal_(terminal),
      plain_period_s_(plain_period_s),
      start_(std::chrono::steady_clock::now()),
      last_(start_) {}

Progress::~Progress() { Finish(); }

double Progress::ElapsedS() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

std::string Progress::Line(const std::string& what, const std::string& phase, int done, int total,
                           double elapsed_s, const std::string& unit) {
  std::string line = what + ": " + (phase.empty() ? "" : phase + " ") + std::to_string(done);
  if (total > 0) line += "/" + std::to_string(total);
  char buffer[128];
  if (total > 0) {
    std::snprintf(buffer, sizeof(buffer), " (%d %%)", static_cast<int>(100.0 * done / total));
    line += buffer;
  }
  if (done > 0 && elapsed_s > 0) {
    const double rate = done / elapsed_s;
    std::snprintf(buffer, sizeof(buffer), ", %.1f %s/s", rate, unit.c_str());
    line += buffer;
    if (done < total) {
      const long left = std::lround((total - done) / rate);
      std::snprintf(buffer, sizeof(buffer), ", %ld:%02ld left", left / 60, left % 60);
      line += buffer;
    }
  }
  return line;
}

void Progress::Set(int done, const std::string& phase) {
  if (!Log().should_log(spdlog::level::info) || (quiet_scopes > 0 && !ignore_quiet_)) return;
  const auto now = std::chrono::steady_clock::now();
  const double since = std::chrono::duration<double>(now - last_).count();
  const bool last = total_ > 0 && done >= total_;
  if (terminal_) {
    if (since < 0.2 && !last) return;
    last_ = now;
    // \r and "clear to the end of the line": the line is rewritten in place.
    // The last count ends the line, so that later messages start on their own.
    std::fprintf(stderr, "\r%s\033[K%s", Line(what_, phase, done, total_, ElapsedS(), unit_).c_str(),
                 last ? "\n" : "");
    std::fflush(stderr);
    line_open_ = !last;
    return;
  }
  if (since < plain_period_s_ && !last) return;
  last_ = now;
  Log().info("{}", Line(what_, phase, done, total_, ElapsedS(), unit_));
}

void Progress::Finish() {
  if (line_open_) {
    std::fputc('\n', stderr);
    std::fflush(stderr);
    line_open_ = false;
  }
}

}  // namespace irbench
