#pragma once
// The scene, rig, avatar, motion and sensor options shared by the subcommands
// that render: `render`, `bench render` and `bench track`.

#include <CLI/CLI.hpp>
#include <string>

#include "sim/sequence/render_job.h"

namespace irbench::cli {

// Binds --scene, --rig, --avatar, --motion, --backend, --supersample, --sensor
// and --shadows to `o`, `backend` and `shadows`; defaults shown are their
// values now.
void AddRenderInputOptions(CLI::App* cmd,
                           RenderJobOptions& o,
                           std::string& backend,
                           std::string& shadows);

// Sets o.shadows from --shadows ("on" or "off"); leaves the default when empty.
void ApplyShadows(const std::string& shadows, RenderJobOptions& o);

// The GL backend --backend names; throws InputError when it names none.
GlBackend BackendOrThrow(const std::string& name);

}  // namespace irbench::cli
