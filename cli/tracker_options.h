#pragma once
// The tracker settings' flags (tracker/pipeline/track_settings.h), shared by
// `irbench track` and `irbench live`.

#include <CLI/CLI.hpp>
#include <string>
#include <utility>
#include <vector>

#include "tracker/pipeline/track_settings.h"

namespace irbench::cli {

// The settings as typed (setting -> text), applied after parsing so that a
// bad value is one InputError naming the flag.
struct TypedTrackerSettings {
  std::vector<std::pair<const TrackSetting*, std::string>> typed;
  void ApplyTo(TrackerSettings& settings) const;
};

// One flag per tracker setting, from the binding table.
void AddTrackerSettingOptions(CLI::App* cmd, TypedTrackerSettings& typed);

}  // namespace irbench::cli
