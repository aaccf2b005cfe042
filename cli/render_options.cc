#include "cli/render_options.h"

#include "cli/option_checks.h"
#include "common/error.h"

namespace irbench::cli {

void AddRenderInputOptions(CLI::App* cmd,
                           RenderJobOptions& o,
                           std::string& backend,
                           std::string& shadows) {
  cmd->add_option("--scene", o.scene, "scene name (scenes/) or file; default: the rig's scene");
  cmd->add_option("--rig", o.rig, "camera rig name (rigs/) or file")->capture_default_str();
  cmd->add_option("--avatar", o.avatar,
                  "avatar name (avatars/), avatar .json, or a rigged mesh (.glb/.gltf/.fbx/.dae)")
      ->capture_default_str();
  cmd->add_option(
         "--motion", o.motion,
         "a library motion (irbench motion list), a file in motions/ (keyframes or session "
         "script), or a path to a .json, .bvh or .amc file")
      ->capture_default_str();
  cmd->add_option("--backend", backend, "OpenGL backend: auto, egl, osmesa or gpu (EGL on the first GPU)")
      ->capture_default_str();
  cmd->add_option("--supersample", o.supersample, "pinhole pixels per output pixel per axis (1-4)")
      ->capture_default_str()
      ->transform(IntegerIn(1, 4));
  cmd->add_option("--sensor", o.sensor, "sensor preset: clean, thesis or harsh")
      ->capture_default_str();
  cmd->add_option(
         "--shadows", shadows,
         "soft shadows of the scene's lights: on or off (default: on unless --sensor clean)")
      ->check(CLI::IsMember({"on", "off"}));
}

void ApplyShadows(const std::string& shadows, RenderJobOptions& o) {
  if (!shadows.empty()) o.shadows = shadows == "on";
}

GlBackend BackendOrThrow(const std::string& name) {
  const auto backend = ParseGlBackend(name);
  if (!backend) throw InputError("", "--backend", "must be auto, egl, osmesa or gpu");
  return *backend;
}

}  // namespace irbench::cli
