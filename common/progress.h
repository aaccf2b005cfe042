#pragma once
// Progress of a long command (render, track, suite): on a terminal, one line
// on stderr rewritten in place with the count done, the rate and the time
// left; when stderr is not a terminal (a log file, CI, a scheduler's output),
// a plain log line every few seconds and at the end. Quiet (-q) shows neither.

#include <chrono>
#include <string>

namespace irbench {

class Progress {
 public:
  // `what`: the command ("render"); `unit`: what is counted, plural
  // ("frame-sets"); `total`: how many there will be (0: not known, as for a
  // live capture: the count and rate without a share or time left).
  Progress(std::string what, std::string unit, int total);
  Progress(std::string what, std::string unit, int total, bool terminal, double plain_period_s);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // `done` of the total are done; `phase` names the current part ("background").
  void Set(int done, const std::string& phase = "");
  // Ends the terminal line (called by the destructor too).
  void Finish();
  // Shows this progress even inside a QuietProgress scope (the suite's own).
  void IgnoreQuiet() { ignore_quiet_ = true; }
  double ElapsedS() const;

  // The line for `done` of `total` after `elapsed_s` seconds:
  // "render: frame 12/60 (20 %), 6.5 frame-sets/s, 0:07 left".
  static std::string Line(const std::string& what, const std::string& phase, int done, int total,
                          double elapsed_s, const std::string& unit);

 private:
  std::string what_, unit_;
  int total_ = 0;
  bool terminal_ = false;
  double plain_period_s_ = 5;
  bool line_open_ = false;
  bool ignore_quiet_ = false;
  std::chrono::steady_clock::time_point start_, last_;
};

// Whether stderr is a terminal.
bool StderrIsTerminal();

// While one lives, Progress shows nothing (unless IgnoreQuiet): for commands
// that run others on several threads (a suite's renders and tracks), whose
// lines would fight over the terminal line.
class QuietProgress {
 public:
  QuietProgress();
  ~QuietProgress();
  QuietProgress(const QuietProgress&) = delete;
  QuietProgress& operator=(const QuietProgress&) = delete;
};

}  // namespace irbench
