#pragma once
// Helpers shared by the closed-loop tests.

#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <algorithm>
#include <string>
#include <vector>

namespace irbench::testing {

// What the irbench program did: its exit code and what it printed.
struct Result {
  int exit_code = -1;
  std::string out, err;
};

inline std::string ReadText(const std::filesystem::path& path);

#ifdef IRBENCH_BINARY_DIR
// Runs the built irbench with `args` (each quoted) in the shell, its stdout
// and stderr captured through files in `dir`. A run killed by a signal (the
// shell's exit code 128 + the signal) prints its command and stderr here: the
// caller's assertion on the exit code alone would not say why.
inline Result RunIrbench(const std::vector<std::string>& args, const std::filesystem::path& dir) {
  std::string command = std::string(IRBENCH_BINARY_DIR) + "/irbench";
  for (const std::string& a : args) command += " '" + a + "'";
  command += " > '" + (dir / "stdout.txt").string() + "' 2> '" + (dir / "stderr.txt").string() + "'";
  const int status = std::system(command.c_str());
  Result r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = ReadText(dir / "stdout.txt");
  r.err = ReadText(dir / "stderr.txt");
  if (r.exit_code > 128) {
    std::fprintf(stderr, "RunIrbench: exit %d (signal %d) from %s\nits stderr:\n%s\n", r.exit_code,
                 r.exit_code - 128, command.c_str(), r.err.c_str());
  }
  return r;
}
#endif

inline std::filesystem::path FreshTempDir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("irbench_test_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

inline void WriteText(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

inline std::string ReadText(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

// The CMU development clips beside the checkout (../shared/data/mocap/cmu),
// sorted; empty when the folder is absent (tests then skip).
inline std::vector<std::filesystem::path> CmuClips() {
  const auto dir = std::filesystem::path(IRBENCH_SOURCE_DIR) / ".." / "shared" / "data" / "mocap" / "cmu";
  std::vector<std::filesystem::path> files;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
    if (e.path().extension() == ".bvh") files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// A short motion with wide arm and body movement, so a few frames cover
// raised, crossed and hidden arms.
inline std::string FastMotionJson() {
  return R"({"format": "irbench.keyframes/1", "name": "fast", "keys": [
    {"t": 0.0, "joints": {"right_shoulder": [0, 80, 0], "left_shoulder": [0, -80, 0]}},
    {"t": 0.1, "root": [0.2, 0.1, 0], "heading_deg": 40,
     "joints": {"right_shoulder": [0, -60, 20], "right_elbow": [0, -40, 0], "left_shoulder": [0, 10, -80],
                "left_elbow": [0, 0, -90], "right_hip": [20, 0, 0], "left_knee": [-30, 0, 0]}},
    {"t": 0.2, "root": [-0.3, -0.2, -0.15], "heading_deg": -60,
     "joints": {"right_shoulder": [0, 20, 100], "right_elbow": [0, 0, 60], "left_shoulder": [0, 60, 0],
                "spine": [15, 0, 0], "right_knee": [-40, 0, 0], "left_hip": [30, 0, 0]}}]})";
}

// A CMU-style ASF skeleton (bone names as in the CMU database, y up, facing
// +z, the subject's left at +x, inches x 0.45 units) and an AMC motion for it:
// the left arm swings down and the right elbow bends over `frames` frames.
inline std::string CmuStyleAsf() {
  struct Bone {
    const char* name;
    double dx, dy, dz, length;
  };
  const Bone bones[] = {
      {"lhipjoint", 1, -1, 0.3, 2.0}, {"lfemur", 0.1, -1, 0, 7.0},  {"ltibia", 0, -1, 0.05, 7.0},
      {"lfoot", 0, -0.3, 1, 2.0},     {"rhipjoint", -1, -1, 0.3, 2.0}, {"rfemur", -0.1, -1, 0, 7.0},
      {"rtibia", 0, -1, 0.05, 7.0},   {"rfoot", 0, -0.3, 1, 2.0},   {"lowerback", 0, 1, 0, 2.0},
      {"upperback", 0, 1, 0, 2.0},    {"thorax", 0, 1, 0, 2.0},     {"lowerneck", 0, 1, 0, 1.5},
      {"upperneck", 0, 1, 0, 1.5},    {"head", 0, 1, 0, 1.5},       {"lclavicle", 1, 0.3, 0, 3.0},
      {"lhumerus", 1, 0, 0, 5.0},     {"lradius", 1, 0, 0, 4.0},    {"lwrist", 1, 0, 0, 1.5},
      {"rclavicle", -1, 0.3, 0, 3.0}, {"rhumerus", -1, 0, 0, 5.0},  {"rradius", -1, 0, 0, 4.0},
      {"rwrist", -1, 0, 0, 1.5}};
  std::string asf =
      "# CMU-style test skeleton\n:version 1.10\n:name test\n:units\n  mass 1.0\n  length 0.45\n"
      "  angle deg\n:documentation\n  written by the tests\n:root\n  order TX TY TZ RX RY RZ\n"
      "  axis XYZ\n  position 0 0 0\n  orientation 0 0 0\n:bonedata\n";
  int id = 1;
  for (const Bone& b : bones) {
    const double n = std::sqrt(b.dx * b.dx + b.dy * b.dy + b.dz * b.dz);
    char text[512];
    std::snprintf(text, sizeof(text),
                  "  begin\n    id %d\n    name %s\n    direction %.6f %.6f %.6f\n    length %.6f\n"
                  "    axis 0 0 %d XYZ\n    dof rx ry rz\n    limits (-180 180)\n (-180 180)\n (-180 180)\n"
                  "  end\n",
                  id, b.name, b.dx / n, b.dy / n, b.dz / n, b.length, (id % 3) * 15);
    ++id;
    asf += text;
  }
  asf +=
      ":hierarchy\n  begin\n    root lhipjoint rhipjoint lowerback\n    lhipjoint lfemur\n"
      "    lfemur ltibia\n    ltibia lfoot\n    rhipjoint rfemur\n    rfemur rtibia\n    rtibia rfoot\n"
      "    lowerback upperback\n    upperback thorax\n    thorax lowerneck lclavicle rclavicle\n"
      "    lowerneck upperneck\n    upperneck head\n    lclavicle lhumerus\n    lhumerus lradius\n"
      "    lradius lwrist\n    rclavicle rhumerus\n    rhumerus rradius\n    rradius rwrist\n  end\n";
  return asf;
}

inline std::string CmuStyleAmc(int frames, const std::string& extra_bone_line = "") {
  std::string amc = "# test motion\n:FULLY-SPECIFIED\n:DEGREES\n";
  for (int f = 1; f <= frames; ++f) {
    const double u = frames > 1 ? double(f - 1) / (frames - 1) : 0.0;
    char text[512];
    std::snprintf(text, sizeof(text),
                  "%d\nroot %.4f 16.5 %.4f 0 %.4f 0\nlhumerus %.4f %.4f %.4f\nlradius 0 %.4f 0\n"
                  "rradius %.4f 0 %.4f\nrhumerus 10 -20 %.4f\n",
                  f, 2.0 * u, 1.0 * u, 20.0 * u, 15.0 * u, -25.0 * u, -70.0 * u, 60.0 * u, 30.0 * u,
                  -50.0 * u, 35.0 * u);
    amc += text;
    if (f == frames) amc += extra_bone_line;
  }
  return amc;
}

}  // namespace irbench::testing
