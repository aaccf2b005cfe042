// `irbench motion list|info|export`: list, inspect and export motions.

#include <iostream>
#include <memory>
#include <string>

#include "cli/commands.h"
#include "cli/option_checks.h"
#include "sim/sequence/motion_tools.h"

namespace irbench::cli {
namespace {

// Adds `motion export`; its flags bind to `options`.
CLI::App* AddMotionExport(CLI::App* motion_cmd, MotionExportOptions& options) {
  CLI::App* cmd = motion_cmd->add_subcommand(
      "export",
      "Write a motion, posed on an avatar, as BVH (Blender, assimp, MotionBuilder open it)");
  cmd->add_option("--motion", options.motion, "motion, as for render --motion")->required();
  cmd->add_option("--avatar", options.avatar,
                  "avatar name (avatars/), avatar .json, or a rigged mesh (.glb/.gltf/.fbx/.dae)")
      ->capture_default_str();
  cmd->add_option("--scene", options.scene, "scene (for pointing targets)")->capture_default_str();
  cmd->add_option("--fps", options.fps, "frames per second")->capture_default_str();
  cmd->add_option("--seed", options.seed, "seed of the person's style")
      ->capture_default_str()
      ->transform(Uint64Text());
  cmd->add_option("OUT", options.out, "output .bvh file")->required();
  cmd->add_flag("--force", options.overwrite, "replace an existing file");
  return cmd;
}

// Prints the library motions and motions/ files.
int RunMotionList() {
  std::cout << MotionListText();
  return kExitOk;
}

// Prints what a BVH or AMC clip holds.
int RunMotionInfo(const std::string& file) {
  std::cout << MotionInfoText(file);
  return kExitOk;
}

// Writes the motion as BVH; prints the file.
int RunMotionExport(const MotionExportOptions& options) {
  std::cout << ExportMotion(options).string() << "\n";
  return kExitOk;
}

}  // namespace

std::vector<Command> AddMotionCommand(CLI::App& app) {
  CLI::App* motion_cmd = app.add_subcommand("motion", "List, inspect and export motions");
  motion_cmd->require_subcommand(1);
  CLI::App* list =
      motion_cmd->add_subcommand("list", "List the library motions and motions/ files");
  auto info_file = std::make_shared<std::string>();
  CLI::App* info = motion_cmd->add_subcommand(
      "info", "Describe a BVH or AMC clip: convention, frames, frame time, the joint map");
  info->add_option("FILE", *info_file, ".bvh or .amc file")->required();
  auto export_options = std::make_shared<MotionExportOptions>();
  CLI::App* export_cmd = AddMotionExport(motion_cmd, *export_options);
  return {{list, RunMotionList},
          {info, [info_file] { return RunMotionInfo(*info_file); }},
          {export_cmd, [export_options] { return RunMotionExport(*export_options); }}};
}

}  // namespace irbench::cli
