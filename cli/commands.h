#pragma once
// The irbench program's subcommands, one file each (cli/<name>_command.cc).
// Each Add*Command registers its subcommand, options and help on the app and
// returns the runnable leaves under it; main parses, then runs the one leaf
// the user picked (Command::Run) and turns its exceptions into exit codes.

#include <CLI/CLI.hpp>
#include <functional>
#include <vector>

namespace irbench::cli {

constexpr int kExitOk = 0;
constexpr int kExitRuntime = 1;
constexpr int kExitBadInput = 2;
constexpr int kExitInterrupted = 130;

// One runnable leaf of the command tree (`render`, `motion list`, ...).
struct Command {
  const CLI::App* subcommand = nullptr;  // picked when subcommand->parsed()
  // Runs it after parsing; returns the exit code. Throws InputError for bad
  // input, Cancelled when interrupted, other exceptions for runtime failures.
  std::function<int()> run;
};

// Adds `render`: a calibrated multi-camera sequence with exact truth.
std::vector<Command> AddRenderCommand(CLI::App& app);
// Adds `track`: the tracker over a sequence folder.
std::vector<Command> AddTrackCommand(CLI::App& app);
// Adds `demo`: render, track and score the default session.
std::vector<Command> AddDemoCommand(CLI::App& app);
// Adds `suite run`: the closed-loop accuracy regression.
std::vector<Command> AddSuiteCommand(CLI::App& app);
// Adds `sweep run|run-one|submit|collect`: stress sweeps.
std::vector<Command> AddSweepCommand(CLI::App& app);
// Adds `score`: a track file against the sequence's truth.
std::vector<Command> AddScoreCommand(CLI::App& app);
// Adds `motion list|info|export`.
std::vector<Command> AddMotionCommand(CLI::App& app);
// Adds `avatar list|info|export`.
std::vector<Command> AddAvatarCommand(CLI::App& app);
// Adds `train rest`: the rest-state SVM.
std::vector<Command> AddTrainCommand(CLI::App& app);
// Adds `fault`: a copy of a sequence with camera faults put in.
std::vector<Command> AddFaultCommand(CLI::App& app);
// Adds `export coco|easymocap`: a sequence as a dataset.
std::vector<Command> AddExportCommand(CLI::App& app);
// Adds `bench render|track`: throughput figures.
std::vector<Command> AddBenchCommand(CLI::App& app);
// `irbench live`: the tracker as frame-sets arrive, over OSC (live_command.cc).
std::vector<Command> AddLiveCommand(CLI::App& app);

}  // namespace irbench::cli
