// irbench: one program, one subcommand per job. Exit codes: 0 success,
// 1 runtime failure, 2 bad input or usage, 130 interrupted.
// Each subcommand lives in its own file (cli/commands.h); this file sets up
// the app and its global flags, parses, runs the picked subcommand and turns
// its exceptions into exit codes.

#include <CLI/CLI.hpp>
#include <exception>
#include <iostream>
#include <utility>
#include <vector>

#include "cli/commands.h"
#include "common/cancel.h"
#include "common/error.h"
#include "common/logging.h"
#include "common/paths.h"

namespace {

using irbench::cli::Command;
using irbench::cli::kExitBadInput;
using irbench::cli::kExitInterrupted;
using irbench::cli::kExitRuntime;

// Registers every subcommand, in the order `irbench --help` lists them.
std::vector<Command> AddCommands(CLI::App& app) {
  using AddCommandFn = std::vector<Command> (*)(CLI::App&);
  std::vector<Command> commands;
  for (AddCommandFn add : {irbench::cli::AddRenderCommand, irbench::cli::AddTrackCommand,
                           irbench::cli::AddDemoCommand, irbench::cli::AddSuiteCommand, irbench::cli::AddSweepCommand,
                           irbench::cli::AddScoreCommand, irbench::cli::AddMotionCommand,
                           irbench::cli::AddAvatarCommand, irbench::cli::AddTrainCommand,
                           irbench::cli::AddFaultCommand, irbench::cli::AddExportCommand, irbench::cli::AddLiveCommand,
                           irbench::cli::AddBenchCommand}) {
    for (Command& command : add(app)) commands.push_back(std::move(command));
  }
  return commands;
}

// Runs the subcommand the user picked; its exceptions become one line on stderr and an exit code.
int RunPickedCommand(const std::vector<Command>& commands) {
  try {
    for (const Command& command : commands) {
      if (command.subcommand->parsed()) return command.run();
    }
  } catch (const irbench::InputError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitBadInput;
  } catch (const irbench::Cancelled&) {
    std::cerr << "interrupted: nothing was left half-written\n";
    return kExitInterrupted;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitRuntime;
  }
  return kExitBadInput;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"irbench: a test bench for multi-camera near-infrared body tracking.\n"
               "Renders calibrated multi-camera sequences with exact truth (render),\n"
               "runs the tracker on them (track) and scores track files against the truth (score).",
               "irbench"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "irbench " + irbench::ToolVersion() + "\ndata root: " + irbench::DataRoot().string());
  int verbosity = 1;
  app.add_flag_callback("-q,--quiet", [&] { verbosity = 0; }, "only warnings and errors on stderr");
  app.add_flag_callback("-v,--verbose", [&] { verbosity = 2; }, "debug messages on stderr");
  const std::vector<Command> commands = AddCommands(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "error: " << e.what() << " (see --help)\n";
    return kExitBadInput;
  }
  irbench::SetVerbosity(verbosity);
  irbench::InstallCancelHandlers();
  return RunPickedCommand(commands);
}
