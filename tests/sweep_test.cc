// `irbench sweep` as a user runs it: a two-point placement sweep of the side
// camera run here two at a time; run again, nothing is redone; one point run
// alone (as a Slurm array task runs it) gives the same bytes; the tables and
// report; the job-array script over the missing points; and the best point's
// rig rendered, tracked and scored alone gives the point's metrics.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <nlohmann/json.hpp>

#include "ci/suite_runner/scenario.h"
#include "ci/sweep/sweep.h"
#include "tests/test_util.h"

namespace irbench {
namespace {
namespace fs = std::filesystem;
using testing::FreshTempDir;
using testing::ReadText;
using testing::WriteText;

using irbench::testing::Result;
using irbench::testing::RunIrbench;

TEST(SweepTest, RunsResumesRunsOnePointAloneAndReproducesTheBest) {
  const fs::path dir = FreshTempDir("sweep");
  const fs::path spec = dir / "side.json";
  WriteText(spec, R"({"format": "irbench.sweep/1", "name": "side2", "description": "two side-camera heights",
    "base": {"rig": "theater4", "avatar": "p1", "motion": "flap_both", "sensor": "thesis", "seed": 4,
             "frames": 8, "background_frames": 4},
    "axes": [{"camera": "side", "along": {"from": [-3.6, 0.4], "to": [-3.6, 0.4]},
              "height": {"from": 1.0, "to": 3.2, "steps": 2}, "look_at": [0, 0, 1.0]}]})");
  const fs::path out = dir / "out", cache = dir / "cache";
  const std::vector<std::string> where = {"--out", out.string(), "--cache", cache.string()};
  const auto with = [&](std::vector<std::string> args) {
    args.insert(args.end(), where.begin(), where.end());
    return args;
  };
  const Result run = RunIrbench(with({"sweep", "run", spec.string(), "--jobs", "2"}), dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("2 of 2 points done"), std::string::npos) << run.out;
  const std::string p0 = ReadText(out / "points" / "p0000.json"), p1 = ReadText(out / "points" / "p0001.json");
  ASSERT_FALSE(p0.empty());
  ASSERT_FALSE(p1.empty());
  const nlohmann::json j0 = nlohmann::json::parse(p0), j1 = nlohmann::json::parse(p1);
  EXPECT_DOUBLE_EQ(j0["coordinates"]["side.height"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(j1["coordinates"]["side.height"].get<double>(), 3.2);
  EXPECT_GT(j0["metrics"]["tracked_fraction"].get<double>(), 0.5);
  // Again: every point is done, nothing runs (the point files stay as they were).
  const auto mtime = fs::last_write_time(out / "points" / "p0001.json");
  const Result again = RunIrbench(with({"sweep", "run", spec.string()}), dir);
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_NE(again.err.find("2 done before, 0 to run"), std::string::npos) << again.err;
  EXPECT_EQ(fs::last_write_time(out / "points" / "p0001.json"), mtime);
  // A lost point: collect says so; the job array holds only it; run alone it
  // gives the same bytes as in the pool.
  fs::remove(out / "points" / "p0001.json");
  const Result partial = RunIrbench(with({"sweep", "collect", spec.string()}), dir);
  EXPECT_EQ(partial.exit_code, 1);
  EXPECT_NE(partial.err.find("1 point(s) not done yet (first p0001)"), std::string::npos) << partial.err;
  const Result submit = RunIrbench(with({"sweep", "submit", spec.string(), "--no-submit", "--sbatch-option=--partition=x"}), dir);
  ASSERT_EQ(submit.exit_code, 0) << submit.err;
  const std::string script = ReadText(out / "slurm" / "sweep-1.sbatch");
  EXPECT_NE(script.find("#SBATCH --array=1\n"), std::string::npos) << script;
  EXPECT_NE(script.find("#SBATCH --partition=x\n"), std::string::npos) << script;
  EXPECT_NE(script.find("sweep run-one"), std::string::npos) << script;
  const Result one = RunIrbench(with({"sweep", "run-one", spec.string(), "1"}), dir);
  ASSERT_EQ(one.exit_code, 0) << one.err;
  EXPECT_EQ(ReadText(out / "points" / "p0001.json"), p1);
  const Result collect = RunIrbench(with({"sweep", "collect", spec.string()}), dir);
  ASSERT_EQ(collect.exit_code, 0) << collect.err;
  const std::string csv = ReadText(out / "sweep.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 3) << csv;
  EXPECT_EQ(csv.rfind("point,side.along,side.height,side.x,side.y,side.z,", 0), 0u) << csv;
  EXPECT_NE(ReadText(out / "report.html").find("<svg"), std::string::npos);
  // The best point by arms_mean_cm, reproduced from its rig alone in another cache.
  const int best = j0["metrics"]["arms_mean_cm"].get<double>() <= j1["metrics"]["arms_mean_cm"].get<double>() ? 0 : 1;
  EXPECT_NE(ReadText(out / "sweep.md").find(std::string("## Best: p000") + char('0' + best)), std::string::npos);
  Scenario alone;
  alone.name = "alone";
  alone.render.rig = (out / "rigs" / (PointName(best) + ".json")).string();
  alone.render.avatar = "p1";
  alone.render.motion = "flap_both";
  alone.render.sensor = "thesis";
  alone.render.seed = 4;
  alone.render.frames = 8;
  alone.render.background_frames = 4;
  std::mutex render_mutex;
  fs::path report;
  fs::create_directories(dir / "cache2");
  const Measured m = RunScenario(alone, "test", dir / "cache2", &render_mutex, &report);
  const nlohmann::json& expected = (best == 0 ? j0 : j1)["metrics"];
  ASSERT_EQ(m.metrics.size(), expected.size());
  for (const auto& [metric, value] : m.metrics) EXPECT_EQ(value, expected[metric].get<double>()) << metric;
  // A bad spec: exit 2, one line naming the file and field, nothing written or submitted.
  WriteText(dir / "bad.json", R"({"format": "irbench.sweep/1", "name": "bad", "base": {},
    "axes": [{"camera": "side", "along": {"from": [-3.6, 0], "to": [-9, 0], "steps": 2}, "height": 2}]})");
  const Result bad = RunIrbench({"sweep", "submit", (dir / "bad.json").string(), "--out", (dir / "bad").string(),
                                 "--cache", cache.string(), "--sbatch", "/bin/false"}, dir);
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find((dir / "bad.json").string() + ": axes[0].along: camera at (-9, 0, 2) lies outside"),
            std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(dir / "bad"));
  // Another spec into the same folder is refused, naming --out.
  WriteText(spec, ReadText(spec).replace(ReadText(spec).find("\"seed\": 4"), 9, "\"seed\": 5"));
  const Result other = RunIrbench(with({"sweep", "run", spec.string()}), dir);
  EXPECT_EQ(other.exit_code, 2);
  EXPECT_NE(other.err.find("--out"), std::string::npos) << other.err;
}

// Runs `command` with /bin/sh; its exit code.
int Shell(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// A one-node Slurm (ci/slurm/local_cluster.sh: munge, slurmctld, slurmd)
// started for the test and stopped after.
class LocalSlurm {
 public:
  explicit LocalSlurm(const fs::path& dir) : dir_(dir) {
    script_ = fs::path(IRBENCH_SOURCE_DIR) / "ci" / "slurm" / "local_cluster.sh";
    fs::create_directories(dir);
    started_ = Shell("'" + script_.string() + "' start '" + dir.string() + "' > '" + (dir / "start.log").string() +
                     "' 2>&1") == 0;
    if (started_) ::setenv("SLURM_CONF", (dir / "slurm.conf").c_str(), 1);
  }
  ~LocalSlurm() {
    Shell("'" + script_.string() + "' stop '" + dir_.string() + "'");
    ::unsetenv("SLURM_CONF");
  }
  bool started() const { return started_; }
  std::string log() const { return ReadText(dir_ / "start.log"); }
  // Waits until job `id` has left the queue (at most `seconds`).
  bool Wait(const std::string& id, int seconds) const {
    for (int i = 0; i < seconds * 5; ++i) {
      if (Shell("squeue -h -j " + id + " 2>/dev/null | grep -q .") != 0) return true;
      Shell("sleep 0.2");
    }
    return false;
  }

 private:
  fs::path dir_, script_;
  bool started_ = false;
};

bool HaveSlurm() {
  return Shell("command -v munged >/dev/null || test -x /usr/sbin/munged") == 0 &&
         Shell("test -x /usr/sbin/slurmctld && test -x /usr/sbin/slurmd && command -v sbatch >/dev/null") == 0;
}

// The same sweep through a real one-node Slurm (job arrays of run-one
// tasks, one per search generation, chained) and here with --jobs 2: the
// same point files, byte for byte; a lost point is submitted again alone.
TEST(SweepTest, SlurmJobArrayGivesTheSameBytesAsRunningHere) {
  if (!HaveSlurm()) GTEST_SKIP() << "no Slurm (apt-get install munge slurmctld slurmd slurm-client)";
  const fs::path dir = FreshTempDir("sweep_slurm");
  const fs::path spec = dir / "search.json";
  // A search: its second generation's array waits for the first's
  // (--dependency) and draws its placements from the first's metrics.
  WriteText(spec, R"({"format": "irbench.sweep/1", "name": "search4",
    "base": {"rig": "theater4", "avatar": "p4", "motion": "wave", "sensor": "thesis", "frames": 6,
             "background_frames": 4},
    "axes": [{"camera": "side", "along": {"from": [-3.6, -1.0], "to": [-3.6, 1.0]}, "height": {"from": 1.2, "to": 2.8}}],
    "mode": "search", "seed": 2, "search": {"population": 2, "generations": 2, "elite": 1}})");
  const fs::path cache = dir / "cache";
  const Result here = RunIrbench({"sweep", "run", spec.string(), "--jobs", "2", "--out", (dir / "here").string(),
                                  "--cache", cache.string()}, dir);
  ASSERT_EQ(here.exit_code, 0) << here.err;
  LocalSlurm slurm(dir / "slurm");
  ASSERT_TRUE(slurm.started()) << slurm.log();
  const std::vector<std::string> where = {"--out", (dir / "there").string(), "--cache", cache.string()};
  const auto submit = [&] {
    std::vector<std::string> args = {"sweep", "submit", spec.string(), "--sbatch-option=--cpus-per-task=1"};
    args.insert(args.end(), where.begin(), where.end());
    const Result r = RunIrbench(args, dir);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    const size_t at = r.out.rfind("submitted: job ");  // the last generation's
    EXPECT_NE(at, std::string::npos) << r.out;
    return at == std::string::npos ? std::string("0") : r.out.substr(at + 15, r.out.find('\n', at) - at - 15);
  };
  const std::string job = submit();
  ASSERT_TRUE(slurm.Wait(job, 300)) << "job " << job << " still queued";
  EXPECT_TRUE(fs::is_regular_file(dir / "there" / "slurm" / "sweep-2.sbatch"));  // generation 1's array
  for (const char* point : {"p0000.json", "p0001.json", "p0002.json", "p0003.json"}) {
    EXPECT_EQ(ReadText(dir / "there" / "points" / point), ReadText(dir / "here" / "points" / point)) << point;
  }
  // A lost point (a task killed): submit again runs it alone.
  fs::remove(dir / "there" / "points" / "p0001.json");
  const std::string again = submit();
  EXPECT_NE(ReadText(dir / "there" / "slurm" / "sweep-3.sbatch").find("#SBATCH --array=1\n"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "there" / "slurm" / "sweep-4.sbatch"));  // generation 1 is done
  ASSERT_TRUE(slurm.Wait(again, 300));
  EXPECT_EQ(ReadText(dir / "there" / "points" / "p0001.json"), ReadText(dir / "here" / "points" / "p0001.json"));
  std::vector<std::string> collect = {"sweep", "collect", spec.string()};
  collect.insert(collect.end(), where.begin(), where.end());
  EXPECT_EQ(RunIrbench(collect, dir).exit_code, 0);
}

}  // namespace
}  // namespace irbench
