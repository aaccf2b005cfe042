#include "tracker/pipeline/track_settings.h"

#include <gtest/gtest.h>

#include <set>

#include "common/error.h"
#include "common/json_reader.h"

namespace irbench {
namespace {

// Each setting has its own key and flag, and its default (the option
// struct's initialiser) is in its range and checks clean.
TEST(TrackSettingsTest, KeysAndFlagsAreUniqueAndDefaultsValid) {
  std::set<std::string> keys, flags;
  const TrackerSettings defaults;
  for (const TrackSetting& s : TrackSettings()) {
    EXPECT_TRUE(keys.insert(s.key).second) << s.key;
    EXPECT_TRUE(flags.insert(s.flag).second) << s.flag;
    EXPECT_EQ(s.flag.rfind("--", 0), 0u) << s.flag;
    EXPECT_FALSE(s.help.empty()) << s.key;
    EXPECT_EQ(SettingProblem(s, defaults), "") << s.key;
    EXPECT_EQ(FindTrackSetting(s.key), &s);
  }
  EXPECT_EQ(FindTrackSetting("no_such"), nullptr);
  EXPECT_NO_THROW(CheckTrackerSettings(defaults));
  EXPECT_EQ(NonDefaultSettingsTag(defaults), "");
  // track.json lists every setting with its default.
  const nlohmann::json j = SettingsJson(defaults);
  EXPECT_EQ(j.size(), TrackSettings().size());
  EXPECT_EQ(j["particles"], 200);
  EXPECT_EQ(j["stage"], "pose");
  EXPECT_EQ(j["background_model"], "flicker");
  EXPECT_EQ(j["remove_shadows"], true);
}

// Text (the command line) and JSON (a suite) reach the same fields of the
// libraries' option structs, and out-of-range values are refused naming the
// flag or the field.
TEST(TrackSettingsTest, TextAndJsonReachTheOptionStructs) {
  TrackerSettings t;
  SetFromText(*FindTrackSetting("particles"), "250", t);
  SetFromText(*FindTrackSetting("stage"), "features", t);
  SetFromText(*FindTrackSetting("background_model"), "plain", t);
  SetFromText(*FindTrackSetting("shadow_edge_scale"), "2", t);
  SetFromText(*FindTrackSetting("hull_missing_views"), "1", t);
  SetFromText(*FindTrackSetting("refine_fraction"), "0.5", t);
  SetFromText(*FindTrackSetting("seed"), "18446744073709551615", t);
  EXPECT_EQ(t.pose.particles, 250);
  EXPECT_EQ(t.stage, TrackStage::kFeatures);
  EXPECT_EQ(t.frontend.background.model, BackgroundKind::kPlain);
  EXPECT_EQ(t.frontend.voxels.max_missing_views, 1);
  EXPECT_EQ(t.pose.refine_fraction, 0.5);
  EXPECT_EQ(t.pose.seed, 18446744073709551615ull);
  // The edge scale multiplies shadow removal's thresholds.
  const FrontEndOptions effective = EffectiveFrontEndOptions(t);
  EXPECT_DOUBLE_EQ(effective.shadow.canny_low, 2 * FrontEndOptions().shadow.canny_low);
  EXPECT_DOUBLE_EQ(effective.shadow.canny_high, 2 * FrontEndOptions().shadow.canny_high);
  EXPECT_EQ(NonDefaultSettingsTag(t),
            "stage=features-particles=250-refine_fraction=0.5-seed=18446744073709551615-background_"
            "model=plain-"
            "shadow_edge_scale=2-hull_missing_views=1");

  for (const auto& [key, text] :
       std::vector<std::pair<std::string, std::string>>{{"particles", "0"},
                                                        {"particles", "12x"},
                                                        {"particles", "1000001"},
                                                        {"stage", "skeleton"},
                                                        {"seed", "-1"},
                                                        {"seed", "18446744073709551616"},
                                                        {"shadow_edge_scale", "9"},
                                                        {"refine_fraction", "1.5"},
                                                        {"hull_missing_views", "2"},
                                                        {"background_model", "mog"}}) {
    const TrackSetting& s = *FindTrackSetting(key);
    TrackerSettings fresh;
    try {
      SetFromText(s, text, fresh);
      ADD_FAILURE() << key << " " << text << " passed";
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), s.flag);
      EXPECT_NE(e.message().find("'" + text + "'"), std::string::npos) << e.message();
    }
  }

  const JsonNode suite = ParseJsonString(
      R"({"particles": 30, "remove_shadows": false, "refine_fraction": 0.25, "particles_bad": 0,
          "scale_bad": 0.1, "model_bad": "mog"})",
      "suite.json");
  TrackerSettings from_json;
  SetFromJson(*FindTrackSetting("particles"), suite["particles"], from_json);
  SetFromJson(*FindTrackSetting("remove_shadows"), suite["remove_shadows"], from_json);
  SetFromJson(*FindTrackSetting("refine_fraction"), suite["refine_fraction"], from_json);
  EXPECT_EQ(from_json.pose.particles, 30);
  EXPECT_FALSE(from_json.frontend.remove_shadows);
  EXPECT_EQ(from_json.pose.refine_fraction, 0.25);
  for (const auto& [key, field] :
       std::vector<std::pair<std::string, std::string>>{{"particles", "particles_bad"},
                                                        {"shadow_edge_scale", "scale_bad"},
                                                        {"background_model", "model_bad"}}) {
    try {
      SetFromJson(*FindTrackSetting(key), suite[field], from_json);
      ADD_FAILURE() << field << " passed";
    } catch (const InputError& e) {
      EXPECT_EQ(e.file(), "suite.json");
      EXPECT_EQ(e.field(), field);
    }
  }
}

}  // namespace
}  // namespace irbench
