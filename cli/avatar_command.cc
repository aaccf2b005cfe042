// `irbench avatar list|info|export`: list, inspect and export avatars.

#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "cli/commands.h"
#include "sim/sequence/avatar_tools.h"

namespace irbench::cli {
namespace {

// What `irbench avatar info` and `avatar export` bind to.
struct AvatarArgs {
  std::string info_name;
  std::string export_name;
  std::filesystem::path out;
  bool force = false;
};

// Adds `avatar export`; its arguments bind to `args`.
CLI::App* AddAvatarExport(CLI::App* avatar_cmd, AvatarArgs& args) {
  CLI::App* cmd = avatar_cmd->add_subcommand(
      "export",
      "Write an avatar as binary glTF (.glb): mesh, skeleton and skin, for Blender or any viewer");
  cmd->add_option("AVATAR", args.export_name,
                  "avatar name (avatars/), avatar .json, or a rigged mesh (.glb/.gltf/.fbx/.dae)")
      ->required();
  cmd->add_option("OUT", args.out, "output .glb file")->required();
  cmd->add_flag("--force", args.force, "replace an existing file");
  return cmd;
}

// Prints the avatars in avatars/.
int RunAvatarList() {
  std::cout << AvatarListText();
  return kExitOk;
}

// Prints an avatar's height, triangles and closedness.
int RunAvatarInfo(const AvatarArgs& args) {
  std::cout << AvatarInfoText(args.info_name);
  return kExitOk;
}

// Writes the avatar as .glb; prints the file.
int RunAvatarExport(const AvatarArgs& args) {
  std::cout << ExportAvatar(args.export_name, args.out, args.force).string() << "\n";
  return kExitOk;
}

}  // namespace

std::vector<Command> AddAvatarCommand(CLI::App& app) {
  auto args = std::make_shared<AvatarArgs>();
  CLI::App* avatar_cmd = app.add_subcommand("avatar", "List, inspect and export avatars");
  avatar_cmd->require_subcommand(1);
  CLI::App* list = avatar_cmd->add_subcommand("list", "List the avatars in avatars/");
  CLI::App* info =
      avatar_cmd->add_subcommand("info", "Height, triangles and closedness of an avatar");
  info->add_option("AVATAR", args->info_name,
                   "avatar name (avatars/), avatar .json, or a rigged mesh (.glb/.gltf/.fbx/.dae)")
      ->required();
  CLI::App* export_cmd = AddAvatarExport(avatar_cmd, *args);
  return {{list, RunAvatarList},
          {info, [args] { return RunAvatarInfo(*args); }},
          {export_cmd, [args] { return RunAvatarExport(*args); }}};
}

}  // namespace irbench::cli
