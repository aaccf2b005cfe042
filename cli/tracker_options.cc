#include "cli/tracker_options.h"

namespace irbench::cli {

void TypedTrackerSettings::ApplyTo(TrackerSettings& settings) const {
  for (const auto& [setting, text] : typed) SetFromText(*setting, text, settings);
}

void AddTrackerSettingOptions(CLI::App* cmd, TypedTrackerSettings& args) {
  for (const TrackSetting& setting : TrackSettings()) {
    if (const auto* flag = std::get_if<BoolBinding>(&setting.binding)) {
      cmd->add_flag_callback(
          setting.flag,
          [&args, &setting, value = flag->flag_value] {
            args.typed.emplace_back(&setting, value ? "true" : "false");
          },
          setting.help);
      continue;
    }
    CLI::Option* option = cmd->add_option_function<std::string>(
        setting.flag,
        [&args, &setting](const std::string& text) { args.typed.emplace_back(&setting, text); },
        setting.help);
    option->type_name(TypeName(setting));
    if (const std::string default_text = DefaultText(setting); !default_text.empty()) {
      option->default_str(default_text);
    }
  }
}

}  // namespace irbench::cli
