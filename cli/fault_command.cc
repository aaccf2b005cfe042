// `irbench fault`: a copy of a sequence with camera faults put in (a camera
// that goes black, freezes, loses frames or writes corrupt files), to test
// the tracker's degradation against the unchanged truth.

#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "sim/sequence/camera_faults.h"

namespace irbench::cli {
namespace {

struct FaultArgs {
  FaultJobOptions job;
  std::string sequence, out;
  std::vector<std::string> faults;
};

int RunFault(FaultArgs& args) {
  args.job.sequence = args.sequence;
  args.job.out = args.out;
  args.job.faults.clear();
  for (const std::string& text : args.faults) args.job.faults.push_back(ParseCameraFault(text, "--fault"));
  std::cout << RunFaultJob(args.job).string() << "\n";
  return kExitOk;
}

}  // namespace

std::vector<Command> AddFaultCommand(CLI::App& app) {
  auto args = std::make_shared<FaultArgs>();
  CLI::App* cmd = app.add_subcommand(
      "fault",
      "Copy a sequence with camera faults put in, for testing the tracker's degradation: the\n"
      "truth is unchanged, the faults are listed in OUT/faults.json. Untouched files are hard\n"
      "links where the file system allows.\n"
      "  irbench fault renders/demo --fault cam2:black:2-8 --out renders/demo-cam2-black");
  cmd->add_option("SEQ", args->sequence, "sequence folder written by render")->required();
  cmd->add_option("--fault", args->faults,
                  "CAMERA:KIND:FROM-TO, seconds; KIND is black (zero frames), freeze (the span's first\n"
                  "frame repeated), drop (files missing) or corrupt (files truncated); repeatable")
      ->required();
  cmd->add_option("--out", args->out, "output folder (a new sequence)")->required();
  cmd->add_flag("--force", args->job.overwrite, "replace an existing output folder irbench wrote");
  return {{cmd, [args] { return RunFault(*args); }}};
}

}  // namespace irbench::cli
