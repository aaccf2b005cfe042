#include "common/atomic_file.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "common/error.h"

namespace irbench {
namespace fs = std::filesystem;
namespace {

fs::path FreshDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("irbench_atomic_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(AtomicFileTest, WritesAndLeavesNoTemporaries) {
  const fs::path dir = FreshDir("write");
  AtomicWriteFile(dir / "a.txt", "hello");
  std::ifstream in(dir / "a.txt");
  std::string text;
  in >> text;
  EXPECT_EQ(text, "hello");
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir)) files += e.is_regular_file();
  EXPECT_EQ(files, 1);
}

TEST(AtomicFileTest, StagingDirVanishesUnlessCommitted) {
  const fs::path dir = FreshDir("staging");
  {
    StagingDir staging(dir / "out", false, "--out");
    AtomicWriteFile(staging.path() / "x", "1");
    EXPECT_FALSE(fs::exists(dir / "out"));
  }
  EXPECT_TRUE(fs::is_empty(dir));
  {
    StagingDir staging(dir / "out", false, "--out");
    AtomicWriteFile(staging.path() / "x", "1");
    staging.Commit();
  }
  EXPECT_TRUE(fs::exists(dir / "out" / "x"));
  EXPECT_THROW(StagingDir(dir / "out", false, "--out"), InputError);
  EXPECT_THROW(StagingDir(dir / "missing" / "out", false, "--out"), InputError);
  {
    StagingDir staging(dir / "out", true, "--out");
    AtomicWriteFile(staging.path() / "y", "2");
    staging.Commit();
  }
  EXPECT_TRUE(fs::exists(dir / "out" / "y"));
  EXPECT_FALSE(fs::exists(dir / "out" / "x"));
}

std::string Read(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The message of the InputError `f` throws; "" when it throws none.
template <typename F>
std::string InputErrorOf(F f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// A pid no process has: a child that has exited and been reaped.
pid_t DeadPid() {
  const pid_t pid = fork();
  if (pid == 0) _exit(0);
  int status = 0;
  waitpid(pid, &status, 0);
  return pid;
}

TEST(AtomicFileTest, CommitMarksTheOutputAndForceReplacesOnlyMarkedFolders) {
  const fs::path dir = FreshDir("marker");
  {
    StagingDir staging(dir / "out", false, "--out", "score");
    staging.Commit();
  }
  EXPECT_TRUE(IsIrbenchOutput(dir / "out"));
  const auto marker = nlohmann::json::parse(Read(dir / "out" / kOutputMarker));
  EXPECT_EQ(marker["command"], "score");
  EXPECT_EQ(marker["format"], "irbench.output/1");
  EXPECT_TRUE(marker.contains("tool_version"));
  // A folder, a file and a link irbench did not write survive --force.
  fs::create_directories(dir / "mine" / "sub");
  std::ofstream(dir / "mine" / "sub" / "precious.txt") << "keep";
  std::ofstream(dir / "file.txt") << "keep";
  fs::create_directory_symlink(dir / "out", dir / "link");
  for (const char* name : {"mine", "file.txt", "link"}) {
    const std::string error = InputErrorOf([&] { StagingDir(dir / name, true, "--out"); });
    EXPECT_NE(error.find("--out"), std::string::npos) << name << ": " << error;
    EXPECT_NE(error.find("not written by irbench"), std::string::npos) << name << ": " << error;
  }
  EXPECT_EQ(Read(dir / "mine" / "sub" / "precious.txt"), "keep");
  EXPECT_EQ(Read(dir / "file.txt"), "keep");
  EXPECT_TRUE(IsIrbenchOutput(dir / "out"));
  // The marked folder is replaced, and the new one marked in turn.
  {
    StagingDir staging(dir / "out", true, "--out", "track");
    staging.Commit();
  }
  EXPECT_EQ(nlohmann::json::parse(Read(dir / "out" / kOutputMarker))["command"], "track");
  // Something that appears meanwhile, not irbench's, is not replaced on Commit.
  StagingDir late(dir / "late", true, "--out");
  fs::create_directory(dir / "late");
  EXPECT_THROW(late.Commit(), InputError);
  EXPECT_TRUE(fs::is_empty(dir / "late"));
}

TEST(AtomicFileTest, OutputMayNotEqualContainOrLieInsideAnInput) {
  const fs::path dir = FreshDir("apart");
  const fs::path seq = dir / "seq";
  for (const char* sub : {"frames/cam", "truth", "calib"}) fs::create_directories(seq / sub);
  std::ofstream(seq / "manifest.json") << "{}";
  std::ofstream(dir / "track.jsonl") << "";
  fs::create_directory_symlink(seq, dir / "alias");
  const std::vector<fs::path> inputs = {seq / "truth", seq / "calib", seq / "manifest.json", dir / "track.jsonl"};
  for (const fs::path& out : {seq, seq / "truth", seq / "truth" / "x", dir, seq / "calib/", dir / "alias",
                              dir / "alias" / "truth", dir / "track.jsonl", fs::path("/")}) {
    const std::string error = InputErrorOf([&] { CheckOutputApart(out, inputs, "--out"); });
    EXPECT_NE(error.find("--out"), std::string::npos) << out << ": '" << error << "'";
  }
  EXPECT_NE(InputErrorOf([&] { CheckOutputApart(seq, inputs, "--out"); }).find("contains the input"),
            std::string::npos);
  EXPECT_NE(InputErrorOf([&] { CheckOutputApart(seq / "truth/x", inputs, "--out"); }).find("lies inside"),
            std::string::npos);
  // Beside the inputs, or inside the sequence but outside what is read: fine.
  for (const fs::path& out : {seq / "track", seq / "score", dir / "other", dir / "alias" / "score"}) {
    EXPECT_EQ(InputErrorOf([&] { CheckOutputApart(out, inputs, "--out"); }), "") << out;
  }
  EXPECT_EQ(InputErrorOf([&] { CheckOutputApart(dir / "x", {fs::path()}, "--out"); }), "");
}

TEST(AtomicFileTest, StagingDirRemovesOrAdoptsOnlyDeadProcessesFolders) {
  const fs::path dir = FreshDir("stale");
  const std::string dead = std::to_string(DeadPid());
  const std::string alive = std::to_string(getppid());
  for (const std::string& name : {".out.partial-" + dead, ".out.partial-" + alive, ".outx.partial-" + dead,
                                  ".out.partial-" + dead + "x", ".out.partial-0" + dead, ".out.old-" + dead}) {
    fs::create_directories(dir / name);
    std::ofstream(dir / name / "frame.png") << name;
  }
  EXPECT_EQ(StaleStagingDirs(dir / "out"), std::vector<fs::path>{dir / (".out.partial-" + dead)});
  {
    StagingDir staging(dir / "out", false, "--out");
    EXPECT_FALSE(staging.adopted());
    EXPECT_TRUE(fs::is_empty(staging.path()));
  }
  EXPECT_FALSE(fs::exists(dir / (".out.partial-" + dead)));
  for (const std::string& name : {".out.partial-" + alive, ".outx.partial-" + dead, ".out.partial-" + dead + "x",
                                  ".out.partial-0" + dead, ".out.old-" + dead}) {
    EXPECT_TRUE(fs::exists(dir / name / "frame.png")) << name;
  }
  // Adopted: the dead process's files carry on under this process's name.
  fs::create_directories(dir / (".out.partial-" + dead));
  std::ofstream(dir / (".out.partial-" + dead) / "frame.png") << "kept";
  {
    StagingDir staging(dir / "out", false, "--out", "render", StagingDir::Stale::kAdopt);
    EXPECT_TRUE(staging.adopted());
    EXPECT_EQ(staging.path().filename(), ".out.partial-" + std::to_string(getpid()));
    EXPECT_EQ(Read(staging.path() / "frame.png"), "kept");
    EXPECT_FALSE(fs::exists(dir / (".out.partial-" + dead)));
    staging.Clear();
    EXPECT_TRUE(fs::is_empty(staging.path()));
    staging.Commit();
  }
  EXPECT_TRUE(IsIrbenchOutput(dir / "out"));
  // Nothing to adopt: a fresh folder.
  StagingDir fresh(dir / "out", true, "--out", "render", StagingDir::Stale::kAdopt);
  EXPECT_FALSE(fresh.adopted());
}

}  // namespace
}  // namespace irbench
