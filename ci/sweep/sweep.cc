#include "ci/sweep/sweep.h"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <mutex>
#include <sstream>
#include <thread>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/file_bytes.h"
#include "common/json_reader.h"
#include "common/logging.h"
#include "common/paths.h"
#include "common/progress.h"

namespace irbench {
namespace fs = std::filesystem;
namespace {

// Runs one point: its scenario rendered (cached), tracked and scored; its
// point file written last, atomically.
void RunPoint(const SweepContext& sweep, int index, std::mutex* render_mutex) {
  const SweepPoint point = PointAt(sweep.spec, index, PointMetrics(sweep));
  const Scenario sc = PointScenario(sweep.spec, point, sweep.out);
  fs::path report;
  const Measured m = RunScenario(sc, "sweep " + sweep.spec.name, sweep.cache, render_mutex, &report);
  nlohmann::json metrics = nlohmann::json::object();
  for (const auto& [metric, value] : m.metrics) metrics[metric] = value;
  const nlohmann::json out = {{"format", "irbench.sweep-point/1"},
                              {"sweep", sweep.spec.name},
                              {"index", index},
                              {"coordinates", PointCoordinates(sweep.spec, point)},
                              {"metrics", metrics},
                              {"report", fs::relative(report, sweep.cache).generic_string()}};
  AtomicWriteFile(PointFile(sweep, index), out.dump(2) + "\n");
}

// Where this program is, for the tasks a scheduler starts.
fs::path ThisProgram() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw RuntimeError("cannot tell where this program is (/proc/self/exe); give --irbench");
  return self;
}

fs::path FindSbatch(const fs::path& given) {
  if (!given.empty()) return given;
  if (const char* env = std::getenv("IRBENCH_SBATCH"); env && *env) return env;
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "/usr/bin:/bin");
  for (std::string dir; std::getline(dirs, dir, ':');) {
    const fs::path candidate = fs::path(dir.empty() ? "." : dir) / "sbatch";
    if (::access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  throw RuntimeError("no sbatch on PATH (install Slurm's client, set IRBENCH_SBATCH, or use --no-submit to "
                     "write the script only)");
}

// Runs `sbatch --parsable [--dependency=afterany:AFTER] script`; returns the
// job id it prints.
std::string RunSbatch(const fs::path& sbatch, const fs::path& script, const std::string& after) {
  const fs::path log = script.parent_path() / (script.stem().string() + ".submit.log");
  const pid_t pid = ::fork();
  if (pid < 0) throw RuntimeError("cannot start sbatch: fork failed");
  if (pid == 0) {
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      ::dup2(fd, 1);
      ::dup2(fd, 2);
    }
    const std::string dependency = "--dependency=afterany:" + after;
    if (after.empty()) {
      ::execl(sbatch.c_str(), "sbatch", "--parsable", script.c_str(), static_cast<char*>(nullptr));
    } else {
      ::execl(sbatch.c_str(), "sbatch", "--parsable", dependency.c_str(), script.c_str(), static_cast<char*>(nullptr));
    }
    ::_exit(127);
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) throw RuntimeError("cannot wait for sbatch");
  }
  std::string printed = ReadFileBytes(log);
  while (!printed.empty() && (printed.back() == '\n' || printed.back() == ' ')) printed.pop_back();
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    throw RuntimeError(sbatch.string() + " refused " + script.string() + ": " + printed);
  }
  // --parsable: "jobid" or "jobid;cluster".
  return printed.substr(0, printed.find(';'));
}

std::string ShellQuote(const std::string& s) {
  std::string out = "'";
  for (const char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// "0-3,7,9-11"
std::string ArrayRanges(const std::vector<int>& indices) {
  std::string out;
  for (size_t i = 0; i < indices.size();) {
    size_t j = i;
    while (j + 1 < indices.size() && indices[j + 1] == indices[j] + 1) ++j;
    out += (out.empty() ? "" : ",") + std::to_string(indices[i]) +
           (j > i ? "-" + std::to_string(indices[j]) : std::string());
    i = j + 1;
  }
  return out;
}

}  // namespace

fs::path PointFile(const SweepContext& sweep, int index) {
  return sweep.out / "points" / (PointName(index) + ".json");
}

SweepContext OpenSweep(const SweepOptions& options) {
  SweepContext sweep;
  sweep.spec = LoadSweepSpec(options.spec);
  sweep.out = options.out.empty() ? OutputRoot() / "renders" / "sweeps" / sweep.spec.name : options.out;
  sweep.cache = options.cache.empty() ? OutputRoot() / "renders" / "cache" : options.cache;
  std::vector<fs::path> inputs = sweep.spec.inputs;
  inputs.push_back(options.spec);
  CheckOutputApart(sweep.out, inputs, "--out");
  CheckOutputApart(sweep.cache, inputs, "--cache");
  const fs::path spec_copy = sweep.out / "spec.json";
  std::error_code ec;
  if (fs::exists(sweep.out, ec) && !fs::is_empty(sweep.out, ec) && !IsIrbenchOutput(sweep.out)) {
    throw InputError("", "--out", "'" + sweep.out.string() + "' holds files irbench did not write (no " +
                                      kOutputMarker + ")");
  }
  if (fs::is_regular_file(spec_copy) && ReadFileBytes(spec_copy) != sweep.spec.canonical) {
    throw InputError("", "--out", "'" + sweep.out.string() + "' holds the points of another spec (" +
                                      spec_copy.string() + "); give another --out or remove it");
  }
  fs::create_directories(sweep.out / "points");
  fs::create_directories(sweep.cache);
  if (!IsIrbenchOutput(sweep.out)) {
    AtomicWriteFile(sweep.out / kOutputMarker,
                    nlohmann::json{{"format", "irbench.output/1"}, {"tool_version", ToolVersion()},
                                   {"command", "sweep"}}.dump() + "\n");
  }
  if (!fs::is_regular_file(spec_copy)) AtomicWriteFile(spec_copy, sweep.spec.canonical);
  return sweep;
}

PointMetric PointMetrics(const SweepContext& sweep) {
  return [&sweep](int index) -> std::optional<double> {
    const fs::path file = PointFile(sweep, index);
    if (!fs::is_regular_file(file)) return std::nullopt;
    const JsonNode metrics = ParseJsonFile(file.string())["metrics"];
    if (!metrics.Has(sweep.spec.metric)) return std::nullopt;
    return metrics[sweep.spec.metric].Number();
  };
}

std::vector<int> MissingPoints(const SweepContext& sweep) {
  std::vector<int> out;
  const int n = PointCount(sweep.spec);
  for (int i = 0; i < n; ++i) {
    if (!fs::is_regular_file(PointFile(sweep, i))) out.push_back(i);
  }
  return out;
}

SweepRun RunSweep(const SweepOptions& options, std::optional<int> only) {
  const SweepContext sweep = OpenSweep(options);
  SweepRun run;
  run.total = PointCount(sweep.spec);
  if (only && (*only < 0 || *only >= run.total)) {
    throw InputError(options.spec.string(), "INDEX",
                     "point " + std::to_string(*only) + " of 0.." + std::to_string(run.total - 1));
  }
  std::vector<int> todo = MissingPoints(sweep);
  run.done_before = run.total - static_cast<int>(todo.size());
  if (only) {
    const bool missing = std::find(todo.begin(), todo.end(), *only) != todo.end();
    todo = missing ? std::vector<int>{*only} : std::vector<int>{};
    if (!missing) Log().info("sweep {}: {} done before", sweep.spec.name, PointName(*only));
  }
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  const size_t workers = std::min<size_t>(todo.size(), options.jobs > 0 ? size_t(options.jobs) : cores);
  if (!only) {
    Log().info("sweep {}: {} point(s), {} done before, {} to run, {} at a time", sweep.spec.name, run.total,
               run.done_before, todo.size(), workers);
  }
  const QuietProgress quiet;
  Progress progress("sweep " + sweep.spec.name, "points", static_cast<int>(todo.size()));
  progress.IgnoreQuiet();
  std::mutex mutex, render_mutex;
  std::exception_ptr interrupted;
  // A generation at a time: a search's points need the generations before.
  for (int g = 0, generations = GenerationCount(sweep.spec); g < generations && run.failed.empty(); ++g) {
    std::vector<int> now;
    for (const int i : todo) {
      if (only || GenerationOf(sweep.spec, i) == g) now.push_back(i);
    }
    std::atomic<size_t> next{0};
    const auto work = [&] {
      for (size_t i; (i = next++) < now.size();) {
        std::string why;
        try {
          RunPoint(sweep, now[i], &render_mutex);
        } catch (const Cancelled&) {
          // Ctrl-C: start no more points; the finished ones stay.
          const std::lock_guard<std::mutex> lock(mutex);
          if (!interrupted) interrupted = std::current_exception();
          next = now.size();
          return;
        } catch (const std::exception& e) {
          why = e.what();
          Log().error("sweep {}: {} failed: {}", sweep.spec.name, PointName(now[i]), why);
        }
        const std::lock_guard<std::mutex> lock(mutex);
        if (why.empty()) {
          ++run.ran;
        } else {
          run.failed.emplace_back(now[i], why);
        }
        progress.Set(run.ran + static_cast<int>(run.failed.size()), "points done");
      }
    };
    const size_t pool_size = std::min(workers, now.size());
    std::vector<std::thread> pool;
    for (size_t w = 1; w < pool_size; ++w) pool.emplace_back(work);
    if (pool_size > 0) work();
    for (std::thread& t : pool) t.join();
    if (interrupted) std::rethrow_exception(interrupted);
    if (only) break;
  }
  std::sort(run.failed.begin(), run.failed.end());
  return run;
}

SlurmSubmission SubmitSweep(const SweepOptions& options, const SlurmOptions& slurm) {
  const SweepContext sweep = OpenSweep(options);
  SlurmSubmission out;
  out.indices = MissingPoints(sweep);
  if (out.indices.empty()) return out;
  const fs::path irbench = slurm.irbench.empty() ? ThisProgram() : fs::absolute(slurm.irbench);
  const fs::path sbatch = slurm.submit ? FindSbatch(slurm.sbatch) : fs::path();
  const fs::path dir = fs::absolute(sweep.out / "slurm");
  fs::create_directories(dir);
  int k = 1;
  while (fs::exists(dir / ("sweep-" + std::to_string(k) + ".sbatch"))) ++k;
  std::string after;
  for (int g = 0, generations = GenerationCount(sweep.spec); g < generations; ++g) {
    std::vector<int> array;
    for (const int i : out.indices) {
      if (GenerationOf(sweep.spec, i) == g) array.push_back(i);
    }
    if (array.empty()) continue;
    const std::string name = "sweep-" + std::to_string(k++);
    const fs::path script = dir / (name + ".sbatch");
    std::ostringstream s;
    s << "#!/bin/sh\n"
      << "# irbench sweep " << sweep.spec.name << ": " << array.size() << " point(s) not done of "
      << PointCount(sweep.spec)
      << (GenerationCount(sweep.spec) > 1 ? " (search generation " + std::to_string(g) + ")" : std::string())
      << "; written by `irbench sweep submit`.\n"
      << "#SBATCH --job-name=irbench-" << sweep.spec.name << "\n"
      << "#SBATCH --array=" << ArrayRanges(array)
      << (slurm.max_parallel > 0 ? "%" + std::to_string(slurm.max_parallel) : std::string()) << "\n"
      << "#SBATCH --output=" << (dir / (name + "-%a.log")).string() << "\n"
      << "#SBATCH --cpus-per-task=2\n";
    for (const std::string& line : slurm.sbatch_lines) s << "#SBATCH " << line << "\n";
    s << "exec " << ShellQuote(irbench.string()) << " sweep run-one "
      << ShellQuote(fs::absolute(options.spec).string()) << " \"$SLURM_ARRAY_TASK_ID\" --out "
      << ShellQuote(fs::absolute(sweep.out).string()) << " --cache " << ShellQuote(fs::absolute(sweep.cache).string())
      << "\n";
    AtomicWriteFile(script, s.str());
    fs::permissions(script, fs::perms::owner_exec | fs::perms::group_exec, fs::perm_options::add);
    out.scripts.push_back(script);
    if (slurm.submit) {
      after = RunSbatch(sbatch, script, after);
      out.job_ids.push_back(after);
    }
  }
  return out;
}

}  // namespace irbench
