// The irbench program as a user meets it: --help everywhere, one clear line and
// exit code 2 for bad input with nothing left behind, SIGINT leaves no
// half-written file.

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Core>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <thread>

#include "tests/test_util.h"

namespace irbench {
namespace {
namespace fs = std::filesystem;
using irbench::testing::FreshTempDir;
using irbench::testing::ReadText;
using irbench::testing::WriteText;

const std::string kIrbench = std::string(IRBENCH_BINARY_DIR) + "/irbench";

using irbench::testing::Result;
using irbench::testing::RunIrbench;

// Entries of `dir` other than the captured output files.
std::vector<std::string> Leftovers(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name != "stdout.txt" && name != "stderr.txt" && name.rfind("input", 0) != 0) {
      names.push_back(name);
    }
  }
  return names;
}

TEST(CliTest, HelpOnEveryCommand) {
  const fs::path dir = FreshTempDir("cli_help");
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"--help"}, {"render", "--help"}, {"bench", "--help"},
        {"bench", "render", "--help"}, {"motion", "--help"}, {"motion", "list", "--help"},
        {"motion", "info", "--help"}, {"motion", "export", "--help"}, {"avatar", "--help"},
        {"avatar", "list", "--help"}, {"avatar", "info", "--help"}, {"avatar", "export", "--help"},
        {"export", "--help"},
        {"track", "--help"}, {"bench", "track", "--help"}, {"score", "--help"}, {"demo", "--help"}, {"suite", "run", "--help"},
        {"fault", "--help"}, {"train", "rest", "--help"}, {"live", "--help"}}) {
    const Result r = RunIrbench(args, dir);
    EXPECT_EQ(r.exit_code, 0);
    EXPECT_NE(r.out.find("Usage:"), std::string::npos) << args.back();
  }
  EXPECT_EQ(RunIrbench({"render", "--no-such-option"}, dir).exit_code, 2);
  EXPECT_EQ(RunIrbench({}, dir).exit_code, 2);
  // live: an unknown OSC host or a bad port is one line, exit 2.
  for (const char* osc : {"no-such-host.invalid:9000", "127.0.0.1:0", "127.0.0.1"}) {
    const Result r = RunIrbench({"live", dir.string(), "--osc", osc}, dir);
    EXPECT_EQ(r.exit_code, 2) << osc;
    EXPECT_NE(r.err.find("--osc"), std::string::npos) << r.err;
  }
  // ... and the tracker's settings are track's flags, checked the same way.
  const Result particles = RunIrbench({"live", dir.string(), "--particles", "0"}, dir);
  EXPECT_EQ(particles.exit_code, 2);
  EXPECT_NE(particles.err.find("--particles"), std::string::npos) << particles.err;
}

const char* kGoodCamera = R"({"name": "c0", "fx": 300, "fy": 300, "cx": 160, "cy": 120,
  "dist": [0, 0, 0, 0, 0], "position": [0, 3, 1], "look_at": [0, 0, 1]})";

std::string RigWith(const std::string& camera) {
  return std::string(R"({"format": "irbench.rig/1", "scene": "theater", "cameras": [)") + camera + "]}";
}

struct BadCase {
  std::string name;
  std::string input_file;  // written as dir/input.json when non-empty
  std::vector<std::string> args;
  std::vector<std::string> message_has;  // file and field
};

TEST(CliTest, BadInputGivesOneLineExitTwoAndNothingBehind) {
  std::string missing_fx = kGoodCamera;
  missing_fx.replace(missing_fx.find("\"fx\": 300, "), 11, "");
  std::string negative_fx = kGoodCamera;
  negative_fx.replace(negative_fx.find("\"fx\": 300"), 9, "\"fx\": -300");
  const std::string good_rig = RigWith(kGoodCamera);
  const std::vector<BadCase> cases = {
      {"missing_intrinsic", RigWith(missing_fx), {"--rig", "@input"}, {"input.json", "cameras[0].fx"}},
      {"negative_focal", RigWith(negative_fx), {"--rig", "@input"}, {"input.json", "cameras[0].fx"}},
      {"unknown_scene", "", {"--scene", "no_such_scene"}, {"--scene", "no_such_scene"}},
      {"truncated_json", good_rig.substr(0, good_rig.size() / 2), {"--rig", "@input"},
       {"input.json", "line"}},
      {"missing_parent", "", {"--out", "@dir/no/such/parent/seq"}, {"--out", "does not exist"}},
      {"bad_backend", "", {"--backend", "vulkan"}, {"--backend"}},
      {"bad_shadows", "", {"--shadows", "maybe"}, {"--shadows"}},
      {"bad_sensor_knob",
       RigWith(std::string(kGoodCamera).substr(0, std::string(kGoodCamera).size() - 1) +
               R"(, "sensor": {"sensor": {"prnu": 5}}})"),
       {"--rig", "@input"},
       {"input.json", "cameras[0].sensor.sensor.prnu"}},
      {"bad_sensor", "", {"--sensor", "foggy"}, {"--sensor"}},
  };
  for (const BadCase& c : cases) {
    const fs::path dir = FreshTempDir("cli_bad_" + c.name);
    std::vector<std::string> args = {"render", "--frames", "2"};
    bool has_out = false;
    for (std::string a : c.args) {
      if (a == "@input") a = (dir / "input.json").string();
      if (a.rfind("@dir", 0) == 0) a = dir.string() + a.substr(4);
      has_out = has_out || a.find("/no/such/") != std::string::npos;
      args.push_back(a);
    }
    if (!has_out) {
      args.push_back("--out");
      args.push_back((dir / "seq").string());
    }
    if (!c.input_file.empty()) WriteText(dir / "input.json", c.input_file);
    const Result r = RunIrbench(args, dir);
    EXPECT_EQ(r.exit_code, 2) << c.name << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << c.name << ": " << r.err;
    for (const std::string& part : c.message_has) {
      EXPECT_NE(r.err.find(part), std::string::npos) << c.name << ": '" << part << "' not in " << r.err;
    }
    EXPECT_TRUE(Leftovers(dir).empty()) << c.name;
  }
}

// Bad motion files: one line naming the file and the line, exit code 2.
TEST(CliTest, BadMotionFilesNameTheLine) {
  const std::string good_bvh =
      "HIERARCHY\nROOT Hips\n{\n\tOFFSET 0 0 0\n\tCHANNELS 6 Xposition Yposition Zposition Zrotation "
      "Xrotation Yrotation\n\tEnd Site\n\t{\n\t\tOFFSET 0 1 0\n\t}\n}\nMOTION\nFrames: 2\n"
      "Frame Time: 0.1\n0 0 0 0 0 0\n0 0 0 0 0 0\n";
  struct Case {
    std::string name, file, text;
    std::vector<std::string> message_has;
  };
  auto replace = [](std::string s, const std::string& a, const std::string& b) {
    return s.replace(s.find(a), a.size(), b);
  };
  const std::vector<Case> cases = {
      {"no_channels", "bad.bvh", replace(good_bvh, "\tCHANNELS 6 Xposition Yposition Zposition Zrotation "
                                                   "Xrotation Yrotation\n", ""), {"bad.bvh", "line 5"}},
      {"short_frame", "bad.bvh", replace(good_bvh, "0 0 0 0 0 0\n0", "0 0 0 0 0\n0"), {"bad.bvh", "line 14"}},
      {"nan", "bad.bvh", replace(good_bvh, "0 0 0 0 0 0\n0 0 0 0 0 0", "0 0 0 0 0 0\n0 0 nan 0 0 0"),
       {"bad.bvh", "line 15"}},
      {"bad_order", "bad.bvh", replace(good_bvh, "Zrotation Xrotation", "Zrotation Zrotation"),
       {"bad.bvh", "line 5"}},
      {"no_arms", "bad.bvh", good_bvh, {"bad.bvh", "joints", "missing"}},
      {"bad_target", "bad.json",
       R"({"format": "irbench.session/1", "items": [{"motion": "point", "target": "moon"}]})",
       {"bad.json", "items[0].target", "moon"}},
      {"bad_library_name", "bad.json",
       R"({"format": "irbench.session/1", "items": [{"motion": "moonwalk"}]})",
       {"bad.json", "items[0]", "moonwalk"}},
      // The AMC's last frame names a bone the ASF lacks: line 3 + 6 lines per frame x 2 + 1.
      {"amc_unknown_bone", "07_01.amc", irbench::testing::CmuStyleAmc(2, "ltail 1 2 3\n"),
       {"07_01.amc", "line 16", "ltail"}},
  };
  for (const Case& c : cases) {
    const fs::path dir = FreshTempDir("cli_motion_" + c.name);
    WriteText(dir / c.file, c.text);
    if (c.file == "07_01.amc") WriteText(dir / "07.asf", irbench::testing::CmuStyleAsf());
    const Result r = RunIrbench({"render", "--frames", "1", "--motion", (dir / c.file).string(), "--out",
                                 (dir / "seq").string()},
                                dir);
    EXPECT_EQ(r.exit_code, 2) << c.name << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << c.name << ": " << r.err;
    for (const std::string& part : c.message_has) {
      EXPECT_NE(r.err.find(part), std::string::npos) << c.name << ": '" << part << "' not in " << r.err;
    }
    EXPECT_FALSE(fs::exists(dir / "seq")) << c.name;
  }
  const fs::path dir = FreshTempDir("cli_motion_name");
  const Result r = RunIrbench({"render", "--motion", "moonwalk", "--out", (dir / "seq").string()}, dir);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("point_horizontal"), std::string::npos) << r.err;  // lists the library
}

// Issue 33.4: `cmake --install` puts the program, its OSMesa module and its
// data under a prefix; the installed program runs from any folder, reads its
// data from <prefix>/share/irbench (not the source tree) and writes default
// outputs under the current folder.
TEST(CliTest, InstalledProgramRunsFromAnywhereWithItsData) {
  const fs::path dir = FreshTempDir("cli_install");
  const fs::path prefix = dir / "prefix";
  const std::string install = "cmake --install '" + std::string(IRBENCH_BINARY_DIR) + "' --prefix '" +
                              prefix.string() + "' > '" + (dir / "install.log").string() + "' 2>&1";
  ASSERT_EQ(std::system(install.c_str()), 0) << ReadText(dir / "install.log");
  for (const char* file : {"bin/irbench", "lib/irbench/libirbench_osmesa.so", "share/irbench/scenes/theater.json",
                           "share/irbench/rigs/theater4.json", "share/irbench/avatars/p1.json",
                           "share/irbench/ci/suites/smoke.json", "share/irbench/tracker/models/rest_svm.yml"}) {
    EXPECT_TRUE(fs::exists(prefix / file)) << file;
  }
  const fs::path work = dir / "work";  // no renders/ yet: the default output makes it
  fs::create_directories(work);
  const auto run = [&](const std::string& args) {
    const std::string command = "cd '" + work.string() + "' && env -u IRBENCH_DATA_DIR '" +
                                (prefix / "bin" / "irbench").string() + "' " + args + " > '" +
                                (dir / "out.txt").string() + "' 2> '" + (dir / "err.txt").string() + "'";
    const int status = std::system(command.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  };
  ASSERT_EQ(run("--version"), 0) << ReadText(dir / "err.txt");
  EXPECT_NE(ReadText(dir / "out.txt").find("data root: " + (prefix / "share" / "irbench").string()), std::string::npos)
      << ReadText(dir / "out.txt");
  // A render by names alone, into ./renders/ (the default output).
  ASSERT_EQ(run("render --rig lab4 --avatar p2 --motion wave --frames 1 --background-frames 0 --supersample 1 "
                "--backend osmesa"),
            0)
      << ReadText(dir / "err.txt");
  EXPECT_TRUE(fs::exists(work / "renders" / "lab4-p2-wave-s1" / "manifest.json")) << ReadText(dir / "out.txt");
}

TEST(CliTest, AvatarExportWritesGlbAndBadAvatarsAreRefused) {
  const fs::path dir = FreshTempDir("cli_avatar");
  const Result r = RunIrbench({"avatar", "export", "p2", (dir / "p2.glb").string()}, dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(ReadText(dir / "p2.glb").substr(0, 4), "glTF");
  const Result info = RunIrbench({"avatar", "info", "p2"}, dir);
  EXPECT_EQ(info.exit_code, 0);
  EXPECT_NE(info.out.find("watertight  yes"), std::string::npos) << info.out;
  // The arm lengths it prints are the rendered truth's bone lengths (which
  // no motion changes) and the bind pose's shoulder width.
  double width = 0, upper_r = 0, upper_l = 0, fore_r = 0, fore_l = 0;
  const size_t arms = info.out.find("arms        ");
  ASSERT_NE(arms, std::string::npos) << info.out;
  ASSERT_EQ(std::sscanf(info.out.c_str() + arms, "arms        shoulder width %lf m; upper arm %lf / %lf m, forearm %lf / %lf m",
                        &width, &upper_r, &upper_l, &fore_r, &fore_l), 5)
      << info.out;
  const Result seq = RunIrbench({"render", "--avatar", "p2", "--motion", "wave", "--frames", "3", "--background-frames",
                                 "0", "--out", (dir / "arms").string()},
                                dir);
  ASSERT_EQ(seq.exit_code, 0) << seq.err;
  std::ifstream truth(dir / "arms" / "truth" / "frames.jsonl");
  std::string line;
  for (int frame = 0; std::getline(truth, line); ++frame) {
    const auto j = nlohmann::json::parse(line)["joints3d"];
    const auto at = [&](const char* name) {
      return Eigen::Vector3d(j[name][0].get<double>(), j[name][1].get<double>(), j[name][2].get<double>());
    };
    EXPECT_NEAR((at("right_elbow") - at("right_shoulder")).norm(), upper_r, 1e-3) << frame;
    EXPECT_NEAR((at("left_elbow") - at("left_shoulder")).norm(), upper_l, 1e-3) << frame;
    EXPECT_NEAR((at("right_wrist") - at("right_elbow")).norm(), fore_r, 1e-3) << frame;
    EXPECT_NEAR((at("left_wrist") - at("left_elbow")).norm(), fore_l, 1e-3) << frame;
    if (frame == 0) {
      EXPECT_NEAR((at("right_shoulder") - at("left_shoulder")).norm(), width, 0.02);
    }
  }
  // A height outside 1.0-2.3 m: one line naming the file and field, exit 2.
  WriteText(dir / "tall.json", R"({"format": "irbench.avatar/1", "kind": "parametric", "height_m": 2.6})");
  for (const auto& args : {std::vector<std::string>{"avatar", "export", (dir / "tall.json").string(),
                                                    (dir / "tall.glb").string()},
                           std::vector<std::string>{"render", "--frames", "1", "--avatar", (dir / "tall.json").string(),
                                                    "--out", (dir / "seq").string()}}) {
    const Result bad = RunIrbench(args, dir);
    EXPECT_EQ(bad.exit_code, 2) << bad.err;
    EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1) << bad.err;
    EXPECT_NE(bad.err.find("tall.json: height_m"), std::string::npos) << bad.err;
  }
  EXPECT_FALSE(fs::exists(dir / "tall.glb"));
  EXPECT_FALSE(fs::exists(dir / "seq"));
}

// Renames nodes in a GLB's JSON chunk (the BIN chunk kept as is); the node named `detach` (after renaming), if any, is cut from
// its parent and made a root of the scene.
void RenameGlbNodes(const fs::path& in, const fs::path& out, const std::map<std::string, std::string>& names,
                    const std::string& detach = "") {
  const std::string bytes = ReadText(in);
  uint32_t json_length = 0;
  std::memcpy(&json_length, bytes.data() + 12, 4);
  auto json = nlohmann::json::parse(bytes.substr(20, json_length));
  for (auto& node : json["nodes"]) {
    const auto it = names.find(node.value("name", ""));
    if (it != names.end()) node["name"] = it->second;
  }
  for (size_t i = 0; i < json["nodes"].size() && !detach.empty(); ++i) {
    if (json["nodes"][i].value("name", "") != detach) continue;
    for (auto& node : json["nodes"]) {
      if (!node.contains("children")) continue;
      auto& kids = node["children"];
      for (auto it = kids.begin(); it != kids.end();) it = *it == i ? kids.erase(it) : std::next(it);
    }
    json["scenes"][0]["nodes"].push_back(i);
  }
  std::string text = json.dump();
  while (text.size() % 4) text += ' ';
  const std::string rest = bytes.substr(20 + json_length);
  std::string glb = bytes.substr(0, 12);
  const uint32_t total = static_cast<uint32_t>(20 + text.size() + rest.size()), length = static_cast<uint32_t>(text.size());
  std::memcpy(glb.data() + 8, &total, 4);
  glb.append(reinterpret_cast<const char*>(&length), 4);
  glb += bytes.substr(16, 4) + text + rest;
  WriteText(out, glb);
}

TEST(CliTest, RiggedMeshesAreAvatarsAndBadOnesAreRefused) {
  const fs::path dir = FreshTempDir("cli_mesh_avatar");
  ASSERT_EQ(RunIrbench({"avatar", "export", "p5", (dir / "p5.glb").string()}, dir).exit_code, 0);
  // The GLB itself works wherever an avatar does.
  const Result info = RunIrbench({"avatar", "info", (dir / "p5.glb").string()}, dir);
  EXPECT_EQ(info.exit_code, 0) << info.err;
  EXPECT_NE(info.out.find("mesh"), std::string::npos) << info.out;
  const Result render = RunIrbench({"render", "--frames", "1", "--background-frames", "0", "--rig", "lab4",
                                    "--avatar", (dir / "p5.glb").string(), "--out", (dir / "ok").string()},
                                   dir);
  EXPECT_EQ(render.exit_code, 0) << render.err;
  const auto manifest = nlohmann::json::parse(ReadText(dir / "ok" / "manifest.json"));
  EXPECT_EQ(manifest["avatar"]["kind"], "mesh");

  // A corrupt GLB (cut short) and a rig with no right arm chain: one line
  // naming the file and field, exit 2, no sequence left behind.
  WriteText(dir / "cut.glb", ReadText(dir / "p5.glb").substr(0, 400));
  // (Renamed joints alone map by the hierarchy's shape; cut from the chest,
  // the arm is no part of the body.)
  RenameGlbNodes(dir / "p5.glb", dir / "no_arm.glb",
                 {{"right_clavicle", "bone_c"}, {"right_shoulder", "bone_a"}, {"right_elbow", "bone_b"}}, "bone_c");
  for (const auto& [file, expected] : {std::pair<std::string, std::string>{"cut.glb", "cut.glb: file: "},
                                       {"no_arm.glb", "no_arm.glb: skin: no arm chain"}}) {
    for (const auto& args :
         {std::vector<std::string>{"avatar", "info", (dir / file).string()},
          std::vector<std::string>{"render", "--frames", "1", "--avatar", (dir / file).string(), "--out",
                                   (dir / "seq").string()}}) {
      const Result bad = RunIrbench(args, dir);
      EXPECT_EQ(bad.exit_code, 2) << bad.err;
      EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1) << bad.err;
      EXPECT_NE(bad.err.find(expected), std::string::npos) << bad.err;
    }
  }
  EXPECT_FALSE(fs::exists(dir / "seq"));
}

TEST(CliTest, TrackWritesFeaturesAndRefusesBadInput) {
  const fs::path dir = FreshTempDir("cli_track");
  ASSERT_EQ(RunIrbench({"render", "--rig", "lab4", "--frames", "2", "--background-frames", "4", "--sensor",
                        "thesis", "--out", (dir / "seq").string()},
                       dir)
                .exit_code,
            0);
  const Result r = RunIrbench({"track", (dir / "seq").string(), "--stage", "features", "--overlays"}, dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const fs::path track = dir / "seq" / "track";
  EXPECT_EQ(r.out, track.string() + "\n");
  std::ifstream lines(track / "features.jsonl");
  std::string line;
  int count = 0;
  while (std::getline(lines, line)) {
    const auto j = nlohmann::json::parse(line);
    EXPECT_EQ(j["frame"], count);
    EXPECT_EQ(j["cameras"].size(), 4u);
    for (const auto& [cam, c] : j["cameras"].items()) {
      EXPECT_GT(c["silhouette_area"].get<int>(), 200) << cam;  // the person is in view
      char name[32];
      std::snprintf(name, sizeof(name), "%06d.png", count);
      EXPECT_TRUE(fs::exists(track / "silhouettes" / cam / name));
      EXPECT_TRUE(fs::exists(track / "overlays" / cam / name));
    }
    ++count;
  }
  EXPECT_EQ(count, 2);
  // The shadow edge scale is recorded with the run (1 unless given).
  const Result scaled = RunIrbench(
      {"track", (dir / "seq").string(), "--stage", "features", "--shadow-edge-scale", "2", "--out",
       (dir / "scaled").string()},
      dir);
  ASSERT_EQ(scaled.exit_code, 0) << scaled.err;
  EXPECT_EQ(nlohmann::json::parse(ReadText(dir / "scaled" / "track.json"))["shadow_edge_scale"], 2.0);
  EXPECT_EQ(nlohmann::json::parse(ReadText(track / "track.json"))["shadow_edge_scale"], 1.0);
  // Every tracker setting of the binding table (track_settings.h) has its
  // flag and lands in track.json: here one declared only there.
  const Result refined = RunIrbench({"track", (dir / "seq").string(), "--stage", "features", "--refine-fraction",
                                     "0.5", "--out", (dir / "refined").string()},
                                    dir);
  ASSERT_EQ(refined.exit_code, 0) << refined.err;
  const auto refined_meta = nlohmann::json::parse(ReadText(dir / "refined" / "track.json"));
  EXPECT_EQ(refined_meta["refine_fraction"], 0.5);
  EXPECT_EQ(refined_meta["particles"], 200);
  EXPECT_EQ(refined_meta["stage"], "features");
  EXPECT_EQ(nlohmann::json::parse(ReadText(track / "track.json"))["refine_fraction"], 0.2);
  // ... and reaches shadow removal: on the thesis preset doubled thresholds
  // lose body edges, so some silhouette changes.
  int changed = 0;
  for (const auto& cam : fs::directory_iterator(track / "silhouettes")) {
    for (const auto& png : fs::directory_iterator(cam.path())) {
      const fs::path other = dir / "scaled" / "silhouettes" / cam.path().filename() / png.path().filename();
      changed += ReadText(png.path()) != ReadText(other);
    }
  }
  EXPECT_GT(changed, 0);
  // The default stage, pose: every frame tracked has the nine scored joints.
  const Result pose = RunIrbench({"track", (dir / "seq").string(), "--out", (dir / "pose").string()}, dir);
  ASSERT_EQ(pose.exit_code, 0) << pose.err;
  std::ifstream pose_lines(dir / "pose" / "track.jsonl");
  int pose_count = 0;
  for (std::string l; std::getline(pose_lines, l); ++pose_count) {
    const auto j = nlohmann::json::parse(l);
    if (j["state"] != "tracking") continue;
    for (const char* joint : {"root", "waist", "neck", "left_shoulder", "left_elbow", "left_wrist", "right_shoulder",
                              "right_elbow", "right_wrist"}) {
      EXPECT_EQ(j["joints3d"][joint].size(), 3u) << joint;
    }
    EXPECT_EQ(j["dof"].size(), 21u);
  }
  EXPECT_EQ(pose_count, 2);
  // Again without --force: refused; an unknown stage, a missing folder, a
  // sequence without empty-stage frames: one line, exit 2, nothing left.
  ASSERT_EQ(RunIrbench({"render", "--rig", "lab4", "--frames", "1", "--background-frames", "0", "--out",
                        (dir / "nobg").string()},
                       dir)
                .exit_code,
            0);
  // Bad recognition models: another format, atoms made for another
  // descriptor size, gesture models without gestures.
  WriteText(dir / "atoms_v9.json", R"({"format": "irbench.posture-atoms/9"})");
  std::string atoms = ReadText(fs::path(IRBENCH_SOURCE_DIR) / "tracker/models/posture_atoms.json");
  ASSERT_NE(atoms.find("\"phi_bins\":24"), std::string::npos);
  atoms.replace(atoms.find("\"phi_bins\":24"), std::string("\"phi_bins\":24").size(), "\"phi_bins\":12");
  WriteText(dir / "atoms_12.json", atoms);
  WriteText(dir / "gestures_none.json",
            R"({"format": "irbench.gesture-models/1", "gestures": [], "atoms": ["A0", "A1"], "models": []})");
  for (const auto& [args, expected] :
       {std::pair<std::vector<std::string>, std::string>{{"track", (dir / "seq").string()}, "exists"},
        {{"track", (dir / "seq").string(), "--posture-atoms", (dir / "atoms_v9.json").string(), "--out",
          (dir / "t10").string()},
         "atoms_v9.json: format: must be irbench.posture-atoms/1"},
        {{"track", (dir / "seq").string(), "--posture-atoms", (dir / "atoms_12.json").string(), "--out",
          (dir / "t10").string()},
         "atoms_12.json: rest.bins: has 13824 bins; the descriptor has 6912"},
        {{"track", (dir / "seq").string(), "--gesture-models", (dir / "gestures_none.json").string(), "--out",
          (dir / "t10").string()},
         "gestures_none.json: gestures: needs at least one gesture"},
        {{"track", (dir / "seq").string(), "--gesture-model", "crf", "--out", (dir / "t10").string()},
         "--gesture-model"},
        {{"track", (dir / "seq").string(), "--motion-labels", (dir / "atoms_v9.json").string(), "--out",
          (dir / "t10").string()},
         "atoms_v9.json: format: must be irbench.motion-labels/1"},
        {{"track", (dir / "seq").string(), "--motion-labels",
          (fs::path(IRBENCH_SOURCE_DIR) / "tracker/models/motion_crf.json").string(), "--out", (dir / "t10").string()},
         "motion_crf.json: kind: is crf, --motion-model asks for ldcrf"},
        {{"track", (dir / "seq").string(), "--motion-model", "hmm", "--out", (dir / "t10").string()},
         "--motion-model"},
        {{"track", (dir / "seq").string(), "--stage", "skeleton", "--out", (dir / "t2").string()}, "--stage"},
        {{"track", (dir / "seq").string(), "--particles", "0", "--out", (dir / "t4").string()}, "--particles"},
        {{"track", (dir / "seq").string(), "--rest-model", (dir / "nosuch.yml").string(), "--out",
          (dir / "t5").string()},
         "nosuch.yml"},
        {{"track", (dir / "seq").string(), "--background-model", "mog", "--out", (dir / "t3").string()},
         "--background-model"},
        {{"track", (dir / "seq").string(), "--shadow-edge-scale", "0", "--out", (dir / "t6").string()},
         "--shadow-edge-scale"},
        {{"track", (dir / "seq").string(), "--refine-fraction", "2", "--out", (dir / "t7").string()},
         "--refine-fraction: '2': must be in 0..1"},
        {{"track", (dir / "seq").string(), "--seed", "-1", "--out", (dir / "t8").string()}, "--seed"},
        {{"track", (dir / "missing").string()}, "no such sequence folder"},
        {{"track", (dir / "seq").string(), "--empty-stage", "2", "--out", (dir / "t9").string()}, "--empty-stage"},
        {{"track", (dir / "seq").string(), "--empty-stage", "0:2", "--out", (dir / "t9").string()},
         "--empty-stage: applies to videos"},
        {{"track", (dir / "seq").string(), "--from-videos", "--out", (dir / "t9").string()}, "videos"},
        {{"track", (dir / "nobg").string()}, "no empty-stage frames"}}) {
    const Result bad = RunIrbench(args, dir);
    EXPECT_EQ(bad.exit_code, 2) << bad.err;
    EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1) << bad.err;
    EXPECT_NE(bad.err.find(expected), std::string::npos) << bad.err;
  }
  for (const char* name : {"t2", "t3", "t4", "t5", "t6", "t7", "t8", "t9", "t10"}) EXPECT_FALSE(fs::exists(dir / name));
  EXPECT_FALSE(fs::exists(dir / "nobg" / "track"));
  // An output that would replace the sequence or land in what it reads
  // (common/atomic_file.h), or a folder irbench did not write.
  fs::create_directories(dir / "mine");
  WriteText(dir / "mine" / "notes.txt", "keep");
  for (const auto& [out, expected] :
       {std::pair<fs::path, std::string>{dir / "seq", "contains the input"},
        {dir, "contains the input"},
        {dir / "seq" / "frames" / "x", "lies inside the input"},
        {dir / "seq" / "calib", "is an input of this command"},
        {dir / "mine", "was not written by irbench"}}) {
    const Result bad = RunIrbench({"track", (dir / "seq").string(), "--out", out.string(), "--force"}, dir);
    EXPECT_EQ(bad.exit_code, 2) << bad.err;
    EXPECT_NE(bad.err.find("--out"), std::string::npos) << bad.err;
    EXPECT_NE(bad.err.find(expected), std::string::npos) << bad.err;
  }
  EXPECT_TRUE(fs::exists(dir / "seq" / "manifest.json"));
  EXPECT_EQ(ReadText(dir / "mine" / "notes.txt"), "keep");
  // The default output, SEQ/track, lies in the sequence but in nothing it
  // reads: replaced with --force, marked as irbench's.
  ASSERT_EQ(RunIrbench({"track", (dir / "seq").string(), "--stage", "features", "--overlays", "--force"}, dir)
                .exit_code,
            0);
  EXPECT_NE(ReadText(track / ".irbench-output").find("\"command\":\"track\""), std::string::npos);

  // An empty stage (the empty-stage frames given as the frames): state "empty",
  // the root null.
  fs::copy(dir / "seq", dir / "empty", fs::copy_options::recursive);
  fs::remove_all(dir / "empty" / "track");
  for (const auto& cam : fs::directory_iterator(dir / "empty" / "frames")) {
    const std::string name = cam.path().filename().string();
    for (const char* frame : {"000000.png", "000001.png"}) {
      fs::copy_file(dir / "empty" / "background" / name / "000000.png", cam.path() / frame,
                    fs::copy_options::overwrite_existing);
    }
  }
  ASSERT_EQ(RunIrbench({"track", (dir / "empty").string()}, dir).exit_code, 0);
  std::ifstream empty_lines(dir / "empty" / "track" / "track.jsonl");
  int empty_count = 0;
  for (std::string l; std::getline(empty_lines, l); ++empty_count) {
    const auto j = nlohmann::json::parse(l);
    EXPECT_EQ(j["state"], "empty");
    EXPECT_TRUE(j["joints3d"]["root"].is_null());
  }
  EXPECT_EQ(empty_count, 2);
  // And the person's sequence is tracked with a root.
  std::ifstream seq_lines(track / "track.jsonl");
  for (std::string l; std::getline(seq_lines, l);) {
    const auto j = nlohmann::json::parse(l);
    EXPECT_EQ(j["state"], "tracking");
    EXPECT_TRUE(j["joints3d"]["root"].is_array());
  }
}

TEST(CliTest, ScorePrintsTheTablesAndRefusesBadInput) {
  const fs::path dir = FreshTempDir("cli_score");
  ASSERT_EQ(RunIrbench({"render", "--rig", "lab4", "--frames", "6", "--background-frames", "0", "--supersample",
                        "1", "--out", (dir / "seq").string()},
                       dir)
                .exit_code,
            0);
  // A track that is the truth with the root 5 cm off.
  std::ifstream truth(dir / "seq/truth/frames.jsonl");
  std::string track;
  for (std::string line; std::getline(truth, line);) {
    auto t = nlohmann::json::parse(line);
    t["joints3d"]["root"][1] = t["joints3d"]["root"][1].get<double>() + 0.05;
    track += nlohmann::json{{"frame", t["frame"]}, {"state", "tracking"}, {"joints3d", t["joints3d"]}}.dump() + "\n";
  }
  WriteText(dir / "track.jsonl", track);
  const Result r = RunIrbench({"score", (dir / "seq").string(), "--track", (dir / "track.jsonl").string()}, dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("| Root | 5.00 | 0.00 | 0 | 6 | 0 |"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("| Waist | 0.00 |"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(dir / "seq/score/score.json"));
  EXPECT_TRUE(fs::exists(dir / "seq/score/errors.csv"));
  EXPECT_TRUE(fs::exists(dir / "seq/score/report.html"));
  WriteText(dir / "bad.jsonl", "{\"frame\": 0, \"joints3d\": {\"root\": \"here\"}}\n");
  for (const auto& [args, expected] :
       {std::pair<std::vector<std::string>, std::string>{{"score", (dir / "seq").string(), "--track",
                                                         (dir / "bad.jsonl").string(), "--out",
                                                         (dir / "s2").string()},
                                                        "bad.jsonl: line 1: root"},
        {{"score", (dir / "seq").string(), "--out", (dir / "s3").string()}, "no such track file"},
        {{"score", (dir / "missing").string(), "--track", (dir / "track.jsonl").string()}, "no such sequence"}}) {
    const Result bad = RunIrbench(args, dir);
    EXPECT_EQ(bad.exit_code, 2) << bad.err;
    EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1) << bad.err;
    EXPECT_NE(bad.err.find(expected), std::string::npos) << bad.err;
  }
  EXPECT_FALSE(fs::exists(dir / "s2"));

  // --force never deletes what the score reads or what irbench did not write:
  // the sequence, its truth, the track's folder, the sequence's parent.
  fs::create_directories(dir / "seq" / "track");
  WriteText(dir / "seq" / "track" / "track.jsonl", track);
  WriteText(dir / "mine.txt", "keep");
  const std::string truth_before = ReadText(dir / "seq/truth/frames.jsonl");
  for (const auto& [out, expected] :
       {std::pair<fs::path, std::string>{dir / "seq", "contains the input"},
        {dir / "seq" / "truth", "is an input of this command"},
        {dir / "seq" / "track", "contains the input"},
        {dir, "contains the input"},
        {dir / "mine.txt", "was not written by irbench"}}) {
    const Result bad = RunIrbench({"score", (dir / "seq").string(), "--out", out.string(), "--force"}, dir);
    EXPECT_EQ(bad.exit_code, 2) << out << ": " << bad.err;
    EXPECT_NE(bad.err.find("--out"), std::string::npos) << bad.err;
    EXPECT_NE(bad.err.find(expected), std::string::npos) << out << ": " << bad.err;
  }
  EXPECT_EQ(ReadText(dir / "seq/truth/frames.jsonl"), truth_before);
  EXPECT_TRUE(fs::exists(dir / "seq/manifest.json"));
  EXPECT_TRUE(fs::exists(dir / "seq/track/track.jsonl"));
  EXPECT_EQ(ReadText(dir / "mine.txt"), "keep");
  // Its own output is replaced with --force.
  EXPECT_EQ(RunIrbench({"score", (dir / "seq").string(), "--force", "--no-report"}, dir).exit_code, 0);

  // A truth without frames is refused; one covering fewer frames than the
  // manifest and the track is scored with warnings.
  fs::create_directories(dir / "short" / "truth");
  fs::copy_file(dir / "seq/manifest.json", dir / "short/manifest.json");
  WriteText(dir / "short/truth/frames.jsonl", "");
  const Result empty = RunIrbench(
      {"score", (dir / "short").string(), "--track", (dir / "track.jsonl").string(), "--no-report"}, dir);
  EXPECT_EQ(empty.exit_code, 2) << empty.out << empty.err;
  EXPECT_NE(empty.err.find("truth/frames.jsonl"), std::string::npos) << empty.err;
  EXPECT_FALSE(fs::exists(dir / "short" / "score"));
  WriteText(dir / "short/truth/frames.jsonl", truth_before.substr(0, truth_before.find('\n') + 1));
  const Result partial = RunIrbench(
      {"score", (dir / "short").string(), "--track", (dir / "track.jsonl").string(), "--no-report"}, dir);
  EXPECT_EQ(partial.exit_code, 0) << partial.err;
  EXPECT_NE(partial.err.find("holds 1 of the 6 frames the manifest lists"), std::string::npos) << partial.err;
  EXPECT_NE(partial.err.find("has frames up to 5"), std::string::npos) << partial.err;
}

TEST(CliTest, DemoRendersTracksAndScores) {
  const fs::path dir = FreshTempDir("cli_demo");
  const Result r = RunIrbench({"demo", "--frames", "8", "--out", (dir / "demo").string()}, dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("| Joint | Mean | Std | Outliers | Total | Missing |"), std::string::npos) << r.out;
  for (const char* file : {"manifest.json", "track/track.jsonl", "track/features.jsonl", "score/score.json", "score/report.html",
                           "score/tables.md"}) {
    EXPECT_TRUE(fs::exists(dir / "demo" / file)) << file;
  }
  // Only the root is tracked so far (and the first 8 frames see the person
  // still entering): what was not scored is null, never a perfect 0.
  const auto score = nlohmann::json::parse(ReadText(dir / "demo" / "score" / "score.json"));
  EXPECT_TRUE(score["joints_cm"]["neck"]["mean"].is_null()) << score["joints_cm"]["neck"].dump();
  EXPECT_EQ(score["joints_cm"]["neck"]["total"], 0);
  // track.json names the model file the track used by content: the shipped
  // rest-state model's SHA-256 as coreutils' sha256sum gives it.
  const auto track = nlohmann::json::parse(ReadText(dir / "demo" / "track" / "track.json"));
  const std::string model = track["models"]["rest_state"]["file"];
  ASSERT_EQ(std::system(("sha256sum '" + model + "' > '" + (dir / "sha.txt").string() + "'").c_str()), 0);
  EXPECT_EQ(ReadText(dir / "sha.txt").substr(0, 64), track["models"]["rest_state"]["sha256"]) << track.dump();
  // Again without --force: refused, the first run kept.
  const Result again = RunIrbench({"demo", "--frames", "8", "--out", (dir / "demo").string()}, dir);
  EXPECT_EQ(again.exit_code, 2);
  EXPECT_NE(again.err.find("exists"), std::string::npos) << again.err;
  EXPECT_TRUE(fs::exists(dir / "demo" / "score/score.json"));
}

// The smoke suite passes against the blessed baselines, and fails when the
// tracker is deliberately degraded (the thesis's plain background model and no
// shadow removal; a 3-particle pose tracker — under the same suite name and
// baselines).
TEST(CliTest, SmokeSuitePassesAndCatchesADegradedTracker) {
  const fs::path dir = FreshTempDir("cli_suite");
  const fs::path smoke = fs::path(IRBENCH_SOURCE_DIR) / "ci" / "suites" / "smoke.json";
  const Result ok = RunIrbench({"suite", "run", "smoke", "--cache", (dir / "cache").string()}, dir);
  EXPECT_EQ(ok.exit_code, 0) << ok.out << ok.err;
  EXPECT_NE(ok.out.find("| p1_flap_both | silhouette_iou_median |"), std::string::npos) << ok.out;
  EXPECT_EQ(ok.out.find("FAIL"), std::string::npos) << ok.out;
  // Every scenario's report.html, listed after the table.
  const size_t listed = ok.out.find("  p1_flap_both  ");
  ASSERT_NE(listed, std::string::npos) << ok.out;
  const size_t from = listed + std::string("  p1_flap_both  ").size();
  EXPECT_TRUE(fs::exists(ok.out.substr(from, ok.out.find('\n', from) - from))) << ok.out;
  // The pooled table (library motions; the CMU clip when ../shared has it)
  // and the suite's own summary page linking each scenario's report.
  EXPECT_NE(ok.out.find("| library | all | 2 |"), std::string::npos) << ok.out;
  const std::vector<fs::path> clips = irbench::testing::CmuClips();
  const bool cmu = std::any_of(clips.begin(), clips.end(), [](const fs::path& c) { return c.stem() == "141_16"; });
  EXPECT_EQ(ok.out.find("| mocap | all | 1 |") != std::string::npos, cmu) << ok.out;
  EXPECT_EQ(ok.out.find("p3_cmu141_16  no motion file") != std::string::npos, !cmu) << ok.out;
  const std::string summary = ReadText(dir / "cache" / "suite-smoke" / "report.html");
  EXPECT_NE(summary.find("<a href=\"../p1_flap_both-"), std::string::npos) << summary;
  EXPECT_NE(summary.find("<th>motion</th><th>person</th>"), std::string::npos) << summary;

  // A suite that includes another and adds an optional scenario whose clip is
  // absent: the included scenarios run from the cache, the absent one is
  // skipped and said so.
  WriteText(dir / "inc.json", R"({"format": "irbench.suite/1", "name": "inc", "include": ["smoke"], "scenarios": [
    {"name": "gone", "motion": "no/such/clip.bvh", "optional": true, "max_seconds": 2,
     "thresholds": {"root_mean_cm": {"max": 10}}},
    {"name": "p1_flap_lib", "avatar": "p1", "motion": "flap_both", "optional": true, "frames": 24, "seed": 1,
     "thresholds": {"root_mean_cm": {"max": 10}}}]})");
  // Blessed: the skipped scenario keeps the figures it had.
  fs::create_directories(dir / "inc_baselines");
  WriteText(dir / "inc_baselines" / "inc.json", R"({"gone": {"root_mean_cm": 1.5}})");
  const Result inc = RunIrbench({"suite", "run", (dir / "inc.json").string(), "--cache", (dir / "cache").string(),
                                 "--bless", "--baselines", (dir / "inc_baselines").string()},
                                dir);
  EXPECT_EQ(inc.exit_code, 0) << inc.out << inc.err;
  const auto inc_blessed = nlohmann::json::parse(ReadText(dir / "inc_baselines" / "inc.json"));
  EXPECT_EQ(inc_blessed["gone"]["root_mean_cm"], 1.5) << inc_blessed.dump();
  EXPECT_TRUE(inc_blessed.contains("p1_flap_lib")) << inc_blessed.dump();
  EXPECT_NE(inc.out.find("| p4_direct_traffic | root_mean_cm |"), std::string::npos) << inc.out;
  EXPECT_NE(inc.out.find("| p1_flap_lib | root_mean_cm |"), std::string::npos) << inc.out;  // a name, not a file
  EXPECT_NE(inc.out.find("  gone  no motion file " + (dir / "no/such/clip.bvh").lexically_normal().string()),
            std::string::npos)
      << inc.out;
  WriteText(dir / "cycle.json", R"({"format": "irbench.suite/1", "name": "c", "include": ["cycle.json"],
    "scenarios": []})");
  const Result cycle = RunIrbench({"suite", "run", (dir / "cycle.json").string(), "--cache", (dir / "cache").string()},
                                  dir);
  EXPECT_EQ(cycle.exit_code, 2) << cycle.err;
  EXPECT_NE(cycle.err.find("cycle.json: include[0]: includes"), std::string::npos) << cycle.err;
  WriteText(dir / "both.json", R"({"format": "irbench.suite/1", "name": "b", "scenarios": [
    {"name": "a", "frames": 4, "max_seconds": 2}]})");
  const Result both = RunIrbench({"suite", "run", (dir / "both.json").string(), "--cache", (dir / "cache").string()},
                                 dir);
  EXPECT_EQ(both.exit_code, 2) << both.err;
  EXPECT_NE(both.err.find("both.json: scenarios[0].max_seconds: give frames or max_seconds"), std::string::npos)
      << both.err;

  auto degraded = nlohmann::json::parse(ReadText(smoke));
  for (auto& scenario : degraded["scenarios"]) {
    scenario["track"] = {{"background_model", "plain"}, {"remove_shadows", false}};
  }
  WriteText(dir / "degraded.json", degraded.dump(2));
  const Result bad = RunIrbench({"suite", "run", (dir / "degraded.json").string(), "--cache", (dir / "cache").string(),
                                 "--baselines", (fs::path(IRBENCH_SOURCE_DIR) / "ci" / "baselines").string()},
                                dir);
  EXPECT_EQ(bad.exit_code, 1) << bad.out << bad.err;
  EXPECT_NE(bad.out.find("regressed from the baseline"), std::string::npos) << bad.out;
  EXPECT_NE(bad.err.find("suite smoke:"), std::string::npos) << bad.err;

  // A degraded pose tracker (3 particles instead of 200), run two scenarios at
  // a time: the arms regress.
  auto few_particles = nlohmann::json::parse(ReadText(smoke));
  for (auto& scenario : few_particles["scenarios"]) scenario["track"] = {{"particles", 3}};
  WriteText(dir / "few_particles.json", few_particles.dump(2));
  const Result weak = RunIrbench({"suite", "run", (dir / "few_particles.json").string(), "--cache",
                                  (dir / "cache").string(), "--jobs", "2", "--baselines",
                                  (fs::path(IRBENCH_SOURCE_DIR) / "ci" / "baselines").string()},
                                 dir);
  EXPECT_EQ(weak.exit_code, 1) << weak.out << weak.err;
  EXPECT_NE(weak.out.find("| arms_mean_cm |"), std::string::npos) << weak.out;
  EXPECT_NE(weak.out.find("regressed from the baseline"), std::string::npos) << weak.out;

  // A bad suite file: one line naming the file and field, exit 2.
  WriteText(dir / "typo.json", R"({"format": "irbench.suite/1", "name": "t", "scenarios": [
    {"name": "a", "thresholds": {"silhouette_iou": {"min": 0.5}}}]})");
  const Result typo = RunIrbench({"suite", "run", (dir / "typo.json").string(), "--cache", (dir / "cache").string()}, dir);
  EXPECT_EQ(typo.exit_code, 2) << typo.err;
  EXPECT_NE(typo.err.find("typo.json: scenarios[0].thresholds.silhouette_iou"), std::string::npos) << typo.err;
  WriteText(dir / "scale.json", R"({"format": "irbench.suite/1", "name": "t", "scenarios": [
    {"name": "a", "track": {"shadow_edge_scale": 9}}]})");
  const Result scale = RunIrbench({"suite", "run", (dir / "scale.json").string(), "--cache", (dir / "cache").string()}, dir);
  EXPECT_EQ(scale.exit_code, 2) << scale.err;
  EXPECT_NE(scale.err.find("scale.json: scenarios[0].track.shadow_edge_scale: must be in 0.25..8"), std::string::npos)
      << scale.err;
  // A setting declared once in the tracker's binding table is a suite key too.
  WriteText(dir / "refine.json", R"({"format": "irbench.suite/1", "name": "t", "scenarios": [
    {"name": "a", "track": {"refine_fraction": 1.5}}]})");
  const Result refine = RunIrbench({"suite", "run", (dir / "refine.json").string(), "--cache", (dir / "cache").string()}, dir);
  EXPECT_EQ(refine.exit_code, 2) << refine.err;
  EXPECT_NE(refine.err.find("refine.json: scenarios[0].track.refine_fraction: must be in 0..1"), std::string::npos)
      << refine.err;
}

TEST(CliTest, MotionExportWritesBvh) {
  const fs::path dir = FreshTempDir("cli_motion_export");
  const Result r = RunIrbench({"motion", "export", "--motion", "flap_one", "--avatar", "p2",
                               (dir / "flap.bvh").string()},
                              dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string bvh = ReadText(dir / "flap.bvh");
  EXPECT_EQ(bvh.rfind("HIERARCHY\nROOT pelvis\n", 0), 0u);
  EXPECT_EQ(RunIrbench({"motion", "export", "--motion", "flap_one", (dir / "flap.bvh").string()}, dir).exit_code,
            2);  // exists
  const Result list = RunIrbench({"motion", "list"}, dir);
  EXPECT_EQ(list.exit_code, 0);
  EXPECT_NE(list.out.find("direct_traffic"), std::string::npos);
  EXPECT_NE(list.out.find("session_demo"), std::string::npos);
}

TEST(CliTest, RenderWritesTheSequenceAndPrintsWhere) {
  const fs::path dir = FreshTempDir("cli_render");
  const Result r = RunIrbench({"render", "--frames", "3", "--background-frames", "1", "--out",
                        (dir / "seq").string()},
                       dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, (dir / "seq").string() + "\n");
  for (const char* file : {"manifest.json", "calib/intri.yml", "calib/extri.yml", "calib/cameras.json",
                           "calib/screens.json", "truth/frames.jsonl",
                           "frames/front_left/000002.png", "truth/masks/side/000000.png",
                           "background/overhead/000000.png"}) {
    EXPECT_TRUE(fs::exists(dir / "seq" / file)) << file;
  }
  EXPECT_EQ(Leftovers(dir), std::vector<std::string>{"seq"});
  // An existing output is refused without --force, replaced with it.
  EXPECT_EQ(RunIrbench({"render", "--frames", "1", "--out", (dir / "seq").string()}, dir).exit_code, 2);
  EXPECT_EQ(RunIrbench({"render", "--frames", "1", "--out", (dir / "seq").string(), "--force"}, dir).exit_code, 0);
  EXPECT_FALSE(fs::exists(dir / "seq/frames/front_left/000002.png"));
  EXPECT_NE(ReadText(dir / "seq" / ".irbench-output").find("\"command\":\"render\""), std::string::npos);
  // --force replaces only a folder irbench wrote, and never one holding an input.
  fs::create_directories(dir / "input-mine");
  WriteText(dir / "input-mine" / "notes.txt", "keep");
  fs::copy_file(fs::path(IRBENCH_SOURCE_DIR) / "rigs" / "lab4.json", dir / "seq" / "rig.json");
  for (const auto& [args, expected] :
       {std::pair<std::vector<std::string>, std::string>{{"--out", (dir / "input-mine").string()},
                                                        "was not written by irbench"},
        {{"--rig", (dir / "seq" / "rig.json").string(), "--out", (dir / "seq").string()}, "contains the input"},
        {{"--rig", (dir / "seq" / "rig.json").string(), "--out", (dir / "seq" / "rig.json").string()},
         "is an input of this command"}}) {
    std::vector<std::string> all = {"render", "--frames", "1", "--force"};
    all.insert(all.end(), args.begin(), args.end());
    const Result bad = RunIrbench(all, dir);
    EXPECT_EQ(bad.exit_code, 2) << bad.err;
    EXPECT_NE(bad.err.find("--out"), std::string::npos) << bad.err;
    EXPECT_NE(bad.err.find(expected), std::string::npos) << bad.err;
  }
  EXPECT_EQ(ReadText(dir / "input-mine" / "notes.txt"), "keep");
  EXPECT_TRUE(fs::exists(dir / "seq" / "rig.json"));
  EXPECT_EQ(Leftovers(dir), std::vector<std::string>{"seq"});
}

// Numbers out of range are refused, never clamped or wrapped, and an empty
// path never means "the default": one line naming the option, exit 2,
// nothing written.
TEST(CliTest, OutOfRangeNumbersAndEmptyPathsAreRefused) {
  const fs::path dir = FreshTempDir("cli_numbers");
  const std::string out = (dir / "out").string(), seq = (dir / "seq").string();
  for (const auto& [args, option] : std::vector<std::pair<std::vector<std::string>, std::string>>{
           {{"render", "--frames", "1", "--seed", "18446744073709551616", "--out", out}, "--seed"},
           {{"render", "--frames", "1", "--seed", "-1", "--out", out}, "--seed"},
           {{"render", "--frames", "1", "--seed", "0x10", "--out", out}, "--seed"},
           {{"render", "--frames", "0", "--out", out}, "--frames"},
           {{"render", "--frames", "-3", "--out", out}, "--frames"},
           {{"render", "--frames", "4294967297", "--out", out}, "--frames"},
           {{"render", "--frames", "1", "--background-frames", "-1", "--out", out}, "--background-frames"},
           {{"render", "--frames", "1", "--supersample", "9", "--out", out}, "--supersample"},
           {{"render", "--frames", "1", "--out", ""}, "--out"},
           {{"demo", "--seed", "-1", "--out", out}, "--seed"},
           {{"demo", "--frames", "0", "--out", out}, "--frames"},
           {{"demo", "--frames", "1", "--out", ""}, "--out"},
           {{"track", seq, "--frames", "0"}, "--frames"},
           {{"track", seq, "--out", ""}, "--out"},
           {{"track", seq, "--particles", "1000000", "--out", out}, "--particles"},
           {{"track", seq, "--particles", "50000", "--out", out}, "--particles"},
           {{"score", seq, "--out", ""}, "--out"},
           {{"suite", "run", "smoke", "--jobs", "0", "--cache", out}, "--jobs"},
           {{"suite", "run", "smoke", "--cache", ""}, "--cache"},
           {{"motion", "export", "--motion", "wave", "--seed", "-1", (dir / "m.bvh").string()}, "--seed"},
           {{"train", "rest", "--folds", "1", "--out", out}, "--folds"},
           {{"train", "rest", "--out", ""}, "--out"},
           {{"train", "atoms", dir.string(), "--selection-table", "", "--out", out}, "--selection-table"},
           {{"train", "atoms", dir.string(), "--selection-table", out + ".md", "--out", out}, "--selection-table"}}) {
    const Result bad = RunIrbench(args, dir);
    EXPECT_EQ(bad.exit_code, 2) << args[0] << " " << option << ": " << bad.err;
    EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1) << bad.err;
    EXPECT_NE(bad.err.find(option), std::string::npos) << bad.err;
    EXPECT_TRUE(Leftovers(dir).empty()) << args[0] << " " << option;
  }
  // The largest seed is a seed.
  const Result big = RunIrbench({"motion", "export", "--motion", "wave", "--seed", "18446744073709551615",
                                 (dir / "m.bvh").string()},
                                dir);
  EXPECT_EQ(big.exit_code, 0) << big.err;
}

// Every file under `root` by its path relative to it, with its bytes.
std::map<std::string, std::string> FilesUnder(const fs::path& root) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(root)) {
    if (e.is_regular_file()) files[fs::relative(e.path(), root).string()] = ReadText(e.path());
  }
  return files;
}

// The staging folders ".<name>.partial-<pid>" in `dir`.
std::vector<std::string> PartialFolders(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name.find(".partial-") != std::string::npos) names.push_back(name);
  }
  return names;
}

// A render killed outright (SIGKILL) leaves its staging folder; `render
// --resume` carries on from the frames its journal lists — cut back here to 7
// frames with a torn 8th line, the last kept frame one the front_left camera
// dropped (it repeats an earlier image, state the resumed run must restore) —
// and ends byte-identical to an uninterrupted render. A staging folder of
// other options is started over.
TEST(CliTest, KilledRenderResumesToTheSameBytes) {
  const fs::path dir = FreshTempDir("cli_resume");
  auto rig = nlohmann::json::parse(ReadText(std::string(IRBENCH_SOURCE_DIR) + "/rigs/lab4.json"));
  rig["cameras"][0]["sensor"] = {{"capture", {{"drop_rate", 0.5}}}};
  rig["cameras"][1]["sensor"] = {{"optics", {{"motion_blur_samples", 3}}}};
  rig["cameras"][2]["sensor"] = {{"capture", {{"sync_jitter_ms", 20.0}}}};
  WriteText(dir / "input-rig.json", rig.dump());
  const std::string first_camera = rig["cameras"][0]["name"];
  std::vector<std::string> args = {"render", "--rig", (dir / "input-rig.json").string(), "--frames", "12",
                                   "--background-frames", "3", "--sensor", "thesis", "--supersample", "1"};
  const auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> all = args;
    all.insert(all.end(), extra.begin(), extra.end());
    return all;
  };
  ASSERT_EQ(RunIrbench(with({"--out", (dir / "ref").string()}), dir).exit_code, 0);
  // The render to kill, once its staging folder holds frame 8.
  std::vector<std::string> argv_strings = with({"--out", (dir / "seq").string()});
  argv_strings.insert(argv_strings.begin(), kIrbench);
  std::vector<char*> argv;
  for (std::string& a : argv_strings) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    freopen((dir / "stderr.txt").c_str(), "w", stderr);
    execv(kIrbench.c_str(), argv.data());
    _exit(127);
  }
  const fs::path partial = dir / (".seq.partial-" + std::to_string(pid));
  for (int i = 0; i < 60000 && !fs::exists(partial / "frames" / first_camera / "000008.png"); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the render ended before it was killed";
  ASSERT_TRUE(fs::is_directory(partial));
  EXPECT_FALSE(fs::exists(dir / "seq"));
  fs::copy(partial, dir / (".other.partial-" + std::to_string(pid)), fs::copy_options::recursive);
  // Keep 7 frames and a torn line, as if killed while appending the 8th.
  const std::string journal = ReadText(partial / ".render-journal/frames.jsonl");
  size_t cut = 0;
  for (int line = 0; line < 7; ++line) cut = journal.find('\n', cut) + 1;
  WriteText(partial / ".render-journal/frames.jsonl", journal.substr(0, cut + 40));
  std::ifstream ref_truth(dir / "ref/truth/frames.jsonl");
  std::string line;
  for (int f = 0; f <= 6; ++f) std::getline(ref_truth, line);
  EXPECT_TRUE(nlohmann::json::parse(line)["sensor"][first_camera]["dropped"].get<bool>())
      << "frame 6 is meant to be a dropped one";

  const Result resumed = RunIrbench(with({"--out", (dir / "seq").string(), "--resume"}), dir);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
  EXPECT_NE(resumed.err.find("resuming after 3 of 3 empty-stage frames and 7 of 12 frames"), std::string::npos)
      << resumed.err;
  EXPECT_EQ(FilesUnder(dir / "seq"), FilesUnder(dir / "ref"));
  EXPECT_EQ(PartialFolders(dir), std::vector<std::string>{".other.partial-" + std::to_string(pid)});

  // Other options (seed 2): the kept frames are not used.
  const Result other = RunIrbench(with({"--seed", "2", "--out", (dir / "other").string(), "--resume"}), dir);
  ASSERT_EQ(other.exit_code, 0) << other.err;
  EXPECT_NE(other.err.find("made with other options"), std::string::npos) << other.err;
  EXPECT_EQ(nlohmann::json::parse(ReadText(dir / "other/manifest.json"))["seed"], 2);
  EXPECT_TRUE(PartialFolders(dir).empty());
}

TEST(CliTest, InterruptLeavesNoHalfWrittenFile) {
  const fs::path dir = FreshTempDir("cli_sigint");
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const std::string out = (dir / "seq").string();
    const std::string log = (dir / "stderr.txt").string();
    freopen(log.c_str(), "w", stderr);
    execl(kIrbench.c_str(), kIrbench.c_str(), "render", "--frames", "5000", "--out", out.c_str(),
          static_cast<char*>(nullptr));
    _exit(127);
  }
  // Wait until frames are being written into the staging folder.
  bool writing = false;
  for (int i = 0; i < 600 && !writing; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    for (const auto& e : fs::directory_iterator(dir)) {
      if (e.path().filename().string().find(".partial-") != std::string::npos &&
          fs::exists(e.path() / "frames/side/000003.png")) {
        writing = true;
      }
    }
  }
  ASSERT_TRUE(writing);
  kill(pid, SIGINT);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 130);
  EXPECT_TRUE(Leftovers(dir).empty());
}

}  // namespace
}  // namespace irbench
