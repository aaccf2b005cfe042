#pragma once
// Resuming an interrupted render (`irbench render --resume`).
//
// While a render runs, its staging folder holds a journal, .render-journal/:
// the hash of everything that decides the render's bytes (options.json) and
// the truth line of each frame-set once all its files are written
// (background.jsonl, frames.jsonl). A render killed outright (SIGKILL, power
// loss) leaves that folder behind; the next render of the same --out with
// --resume adopts it (StagingDir::Stale::kAdopt), keeps the frame-sets the
// journal lists and carries on after them.
//
// Identical bytes: every random draw is seeded per frame (sensor noise by the
// frame index, sync jitter and drops by seed, camera and frame, flicker by
// time), so the only state carried from one frame-set to the next is each
// camera's last written image and its flicker level (a dropped frame repeats
// them; sim/sensor/exposure.h). The resumed run therefore renders again from
// the earliest of the cameras' last frame-sets that was not dropped
// (ReplayStart) and checks those frame-sets against the kept files and
// journal lines byte for byte instead of writing them; a difference
// (ResumeMismatch) means the kept frames were not made this way, and the
// render starts over.

#include <filesystem>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/atomic_file.h"

namespace irbench {

// "000042.png": the name of frame `frame` in a camera's folder.
std::string FrameFileName(int frame, const char* ext);

// What the journal of an adopted staging folder keeps: the truth lines (each
// ending in "\n") of the frame-sets whose files are all there, in order.
struct RenderJournal {
  std::vector<std::string> background_lines;
  std::vector<std::string> frame_lines;
};

// The layout a journal's kept frame-sets are checked against.
struct RenderLayout {
  std::vector<std::string> cameras;
  int background_frames = 0;
  int frames = 0;
  bool depth = false;  // truth/depth/<cam>/NNNNNN.exr per frame
};

// Hex hash of what decides a render's bytes: its manifest (options, inputs'
// names, renderer, tool version) and the contents of its input files.
std::string RenderOptionsHash(const nlohmann::json& manifest, const std::vector<std::filesystem::path>& input_files);

// Starts the journal in `staging`. An adopted folder made with the same
// `hash` keeps its journal (returned; temporary files of the dead process
// removed); one made otherwise is emptied, with a warning. A fresh folder gets
// `hash` written and an empty journal.
RenderJournal StartRenderJournal(StagingDir& staging, const std::string& hash, const RenderLayout& layout);

// Appends frame-set's truth line `line` (with its "\n") to the journal's
// `kind` ("background" or "frames") once its files are written.
void AppendToJournal(const std::filesystem::path& root, const char* kind, const std::string& line);

// Removes the journal from `root` (before the folder is committed).
void RemoveRenderJournal(const std::filesystem::path& root);

// The first frame-set to render again after the kept `lines` so that every
// camera's last written image is what it was: the earliest over `cameras` of
// its last frame-set that was not dropped; 0 when nothing is kept.
int ReplayStart(const std::vector<std::string>& lines, const std::vector<std::string>& cameras);

// A frame-set rendered again differs from the kept one.
class ResumeMismatch : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Writes `bytes` to `path` atomically or, with `verify`, checks that `path`
// holds exactly them (ResumeMismatch naming the file otherwise).
void WriteOrVerify(const std::filesystem::path& path, const std::string& bytes, bool verify);

}  // namespace irbench
