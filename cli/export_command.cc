// `irbench export`: a rendered sequence as a COCO keypoints or EasyMocap
// dataset (sim/sequence/dataset_export.h).

#include <iostream>
#include <memory>
#include <string>

#include "cli/commands.h"
#include "common/error.h"
#include "sim/sequence/dataset_export.h"

namespace irbench::cli {
namespace {

struct ExportArgs {
  DatasetExportOptions job;
  std::string format, sequence, out;
};

int RunExport(ExportArgs& args) {
  const auto format = ParseDatasetFormat(args.format);
  if (!format) throw InputError("", "FORMAT", "'" + args.format + "': use coco or easymocap");
  args.job.format = *format;
  args.job.sequence = args.sequence;
  args.job.out = args.out;
  std::cout << RunDatasetExport(args.job).string() << "\n";
  return kExitOk;
}

}  // namespace

std::vector<Command> AddExportCommand(CLI::App& app) {
  auto args = std::make_shared<ExportArgs>();
  CLI::App* cmd = app.add_subcommand(
      "export",
      "Write a rendered sequence as a dataset other tools read (docs/truth.md, Dataset exports):\n"
      "  coco       OUT/images/<cam>/NNNNNN.png and OUT/annotations/person_keypoints.json (COCO\n"
      "             person keypoints from the truth, boxes, areas and RLE masks from its masks)\n"
      "  easymocap  OUT/images/<cam>/, intri.yml, extri.yml, annots/<cam>/ (2D, BODY_25) and\n"
      "             keypoints3d/ (the truth's 3D joints, BODY_25)\n"
      "Frames are hard links where the file system allows.\n"
      "  irbench export coco renders/demo --out datasets/demo-coco");
  cmd->add_option("FORMAT", args->format, "coco or easymocap")->required();
  cmd->add_option("SEQ", args->sequence, "sequence folder written by render")->required();
  cmd->add_option("--out", args->out, "output folder")->required();
  cmd->add_flag("--force", args->job.overwrite, "replace an existing output folder irbench wrote");
  return {{cmd, [args] { return RunExport(*args); }}};
}

}  // namespace irbench::cli
