#include "sim/sequence/render_resume.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "common/error.h"
#include "common/file_bytes.h"
#include "common/logging.h"

namespace irbench {
namespace fs = std::filesystem;

namespace {

constexpr char kJournalDir[] = ".render-journal";

// The complete lines of a journal file whose "frame" counts 0, 1, ...: a
// line cut short by the kill, or anything after it, is dropped.
std::vector<std::string> JournalLines(const fs::path& path, int max_lines) {
  std::vector<std::string> lines;
  const std::string text = ReadFileBytes(path);
  size_t from = 0;
  for (size_t end; (end = text.find('\n', from)) != std::string::npos && int(lines.size()) < max_lines;
       from = end + 1) {
    const std::string line = text.substr(from, end - from + 1);
    const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
    if (j.is_discarded() || !j.is_object() || j.value("frame", -1) != int(lines.size())) break;
    lines.push_back(line);
  }
  return lines;
}

// How many of the first `count` frame-sets under `dir` (background or frames)
// have every file: written atomically, a file that is there is complete.
int FramesWithFiles(const fs::path& root, const char* dir, int count, const RenderLayout& layout, bool truth) {
  for (int f = 0; f < count; ++f) {
    for (const std::string& cam : layout.cameras) {
      bool present = fs::is_regular_file(root / dir / cam / FrameFileName(f, "png"));
      if (truth) {
        present = present && fs::is_regular_file(root / "truth" / "masks" / cam / FrameFileName(f, "png"));
        if (layout.depth) present = present && fs::is_regular_file(root / "truth" / "depth" / cam / FrameFileName(f, "exr"));
      }
      if (!present) return f;
    }
  }
  return count;
}

// Removes the temporary files (".<name>.tmp-<pid>") a killed process left.
void RemoveTemporaries(const fs::path& root) {
  std::vector<fs::path> temporaries;
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_regular_file() && name.size() > 1 && name[0] == '.' && name.find(".tmp-") != std::string::npos) {
      temporaries.push_back(entry.path());
    }
  }
  for (const fs::path& p : temporaries) fs::remove(p);
}

// The journal of an adopted folder made with `hash`: its frame-sets with all
// their files, the frames only once every empty-stage frame is kept.
RenderJournal KeptJournal(const fs::path& root, const RenderLayout& layout) {
  RenderJournal kept;
  const fs::path journal = root / kJournalDir;
  kept.background_lines = JournalLines(journal / "background.jsonl", layout.background_frames);
  kept.background_lines.resize(
      FramesWithFiles(root, "background", int(kept.background_lines.size()), layout, false));
  if (int(kept.background_lines.size()) == layout.background_frames) {
    kept.frame_lines = JournalLines(journal / "frames.jsonl", layout.frames);
    kept.frame_lines.resize(FramesWithFiles(root, "frames", int(kept.frame_lines.size()), layout, true));
  }
  return kept;
}

// Rewrites the journal's `kind` file to hold `lines` only.
void RewriteJournal(const fs::path& root, const char* kind, const std::vector<std::string>& lines) {
  std::string text;
  for (const std::string& line : lines) text += line;
  AtomicWriteFile(root / kJournalDir / (std::string(kind) + ".jsonl"), text);
}

}  // namespace

std::string FrameFileName(int frame, const char* ext) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%06d.%s", frame, ext);
  return buffer;
}

std::string RenderOptionsHash(const nlohmann::json& manifest, const std::vector<fs::path>& input_files) {
  std::string key = manifest.dump();
  for (const fs::path& file : input_files) {
    if (!file.empty() && fs::is_regular_file(file)) key += "|" + ReadFileBytes(file);
  }
  char hex[20];
  std::snprintf(hex, sizeof(hex), "%016llx", static_cast<unsigned long long>(Fnv1a64(key)));
  return hex;
}

RenderJournal StartRenderJournal(StagingDir& staging, const std::string& hash, const RenderLayout& layout) {
  const fs::path root = staging.path();
  const fs::path options_file = root / kJournalDir / "options.json";
  RenderJournal kept;
  if (staging.adopted()) {
    const nlohmann::json made = nlohmann::json::parse(ReadFileBytes(options_file), nullptr, false);
    if (!made.is_discarded() && made.is_object() && made.value("hash", "") == hash) {
      RemoveTemporaries(root);
      kept = KeptJournal(root, layout);
      Log().info("render: resuming after {} of {} empty-stage frames and {} of {} frames", kept.background_lines.size(),
                 layout.background_frames, kept.frame_lines.size(), layout.frames);
    } else {
      Log().warn("render: the unfinished render in {} was made with other options or inputs (or kept no "
                 "journal); starting over",
                 root.string());
      staging.Clear();
    }
  }
  fs::create_directories(root / kJournalDir);
  AtomicWriteFile(options_file, nlohmann::json{{"hash", hash}}.dump() + "\n");
  RewriteJournal(root, "background", kept.background_lines);
  RewriteJournal(root, "frames", kept.frame_lines);
  return kept;
}

void AppendToJournal(const fs::path& root, const char* kind, const std::string& line) {
  const fs::path path = root / kJournalDir / (std::string(kind) + ".jsonl");
  std::FILE* f = std::fopen(path.c_str(), "ab");
  if (f == nullptr) throw RuntimeError("cannot open " + path.string());
  const size_t written = std::fwrite(line.data(), 1, line.size(), f);
  if (std::fclose(f) != 0 || written != line.size()) throw RuntimeError("cannot write " + path.string());
}

void RemoveRenderJournal(const fs::path& root) { fs::remove_all(root / kJournalDir); }

int ReplayStart(const std::vector<std::string>& lines, const std::vector<std::string>& cameras) {
  int first = static_cast<int>(lines.size());
  for (const std::string& cam : cameras) {
    int last_written = 0;
    for (int f = static_cast<int>(lines.size()) - 1; f >= 0; --f) {
      const nlohmann::json j = nlohmann::json::parse(lines[f]);
      const nlohmann::json* sensor = j.contains("sensor") && j["sensor"].contains(cam) ? &j["sensor"][cam] : nullptr;
      if (sensor == nullptr || !sensor->value("dropped", false)) {
        last_written = f;
        break;
      }
    }
    first = std::min(first, last_written);
  }
  return first;
}

void WriteOrVerify(const fs::path& path, const std::string& bytes, bool verify) {
  if (!verify) {
    AtomicWriteFile(path, bytes);
  } else if (ReadFileBytes(path) != bytes) {
    throw ResumeMismatch(path.string() + " differs when rendered again");
  }
}

}  // namespace irbench
