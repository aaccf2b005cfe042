#include "sim/sequence/camera_faults.h"

#include <cmath>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/file_bytes.h"
#include "common/logging.h"
#include "sequence_format/calibration.h"
#include "sim/sequence/render_resume.h"  // FrameFileName

namespace irbench {
namespace fs = std::filesystem;
namespace {

const char* FaultKindName(CameraFaultKind kind) {
  switch (kind) {
    case CameraFaultKind::kBlack: return "black";
    case CameraFaultKind::kFreeze: return "freeze";
    case CameraFaultKind::kDrop: return "drop";
    case CameraFaultKind::kCorrupt: return "corrupt";
  }
  return "black";
}

double ParseSeconds(const std::string& text, const std::string& whole, const std::string& option) {
  size_t used = 0;
  double v = 0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || !std::isfinite(v) || v < 0 || v > 1e6) {
    throw InputError("", option, "'" + whole + "': '" + text + "' is not a time in seconds (0 to 1e6)");
  }
  return v;
}


// Copies the sequence tree: hard links where the file system allows (the
// faults replace files by rename, never write through a link), else copies.
// Outputs made from the sequence (a track/, a score/: folders carrying the
// output marker) are not copied: they describe the intact sequence.
void LinkTree(const fs::path& from, const fs::path& to) {
  for (auto it = fs::recursive_directory_iterator(from); it != fs::recursive_directory_iterator(); ++it) {
    const fs::directory_entry& entry = *it;
    const fs::path rel = entry.path().lexically_relative(from);
    // The marker and hidden staging leftovers are not part of the sequence.
    if (rel.filename().string().rfind(".", 0) == 0) {
      if (entry.is_directory()) it.disable_recursion_pending();
      continue;
    }
    const fs::path target = to / rel;
    if (entry.is_directory() && IsIrbenchOutput(entry.path())) {
      it.disable_recursion_pending();
    } else if (entry.is_directory()) {
      fs::create_directories(target);
    } else if (entry.is_regular_file()) {
      std::error_code ec;
      fs::create_hard_link(entry.path(), target, ec);
      if (ec) fs::copy_file(entry.path(), target);
    }
  }
}

void WriteImage(const fs::path& path, const cv::Mat& image) {
  std::vector<uchar> bytes;
  if (!cv::imencode(".png", image, bytes)) throw RuntimeError("cannot encode " + path.string());
  AtomicWriteFile(path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

// Applies one fault to the copy at `root`; returns the frames it touched.
int ApplyFault(const CameraFault& fault, const fs::path& root, double fps, int frame_count) {
  const fs::path folder = root / "frames" / fault.camera;
  const int first = static_cast<int>(std::ceil(fault.from_s * fps - 1e-9));
  const int end = std::min(frame_count, static_cast<int>(std::ceil(fault.to_s * fps - 1e-9)));
  cv::Mat frozen;
  int touched = 0;
  for (int f = first; f < end; ++f) {
    const fs::path path = folder / FrameFileName(f, "png");
    if (!fs::exists(path)) continue;  // already dropped
    ++touched;
    switch (fault.kind) {
      case CameraFaultKind::kBlack: {
        const cv::Mat image = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
        if (image.empty()) throw InputError(path.string(), "", "unreadable image");
        WriteImage(path, cv::Mat::zeros(image.size(), image.type()));
        break;
      }
      case CameraFaultKind::kFreeze:
        if (frozen.empty()) {
          frozen = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
          if (frozen.empty()) throw InputError(path.string(), "", "unreadable image");
        } else {
          WriteImage(path, frozen);
        }
        break;
      case CameraFaultKind::kDrop: fs::remove(path); break;
      case CameraFaultKind::kCorrupt: {
        const std::string bytes = ReadFileBytes(path);
        AtomicWriteFile(path, std::string_view(bytes).substr(0, std::min<size_t>(bytes.size(), 64)));
        break;
      }
    }
  }
  return touched;
}

}  // namespace

CameraFault ParseCameraFault(const std::string& text, const std::string& option) {
  const size_t a = text.find(':');
  const size_t b = a == std::string::npos ? a : text.find(':', a + 1);
  const size_t dash = b == std::string::npos ? b : text.find('-', b + 1);
  if (a == 0 || dash == std::string::npos) {
    throw InputError("", option, "'" + text + "' is not CAMERA:KIND:FROM-TO (e.g. cam2:black:2-8)");
  }
  CameraFault fault;
  fault.camera = text.substr(0, a);
  const std::string kind = text.substr(a + 1, b - a - 1);
  if (kind == "black") {
    fault.kind = CameraFaultKind::kBlack;
  } else if (kind == "freeze") {
    fault.kind = CameraFaultKind::kFreeze;
  } else if (kind == "drop") {
    fault.kind = CameraFaultKind::kDrop;
  } else if (kind == "corrupt") {
    fault.kind = CameraFaultKind::kCorrupt;
  } else {
    throw InputError("", option, "'" + text + "': kind '" + kind + "' is not black, freeze, drop or corrupt");
  }
  fault.from_s = ParseSeconds(text.substr(b + 1, dash - b - 1), text, option);
  fault.to_s = ParseSeconds(text.substr(dash + 1), text, option);
  if (!(fault.to_s > fault.from_s)) throw InputError("", option, "'" + text + "': the span ends before it starts");
  return fault;
}

fs::path RunFaultJob(const FaultJobOptions& options) {
  if (options.out.empty()) throw InputError("", "--out", "must not be empty");
  if (options.faults.empty()) throw InputError("", "--fault", "give at least one fault");
  const Calibration calibration = ReadCalibration(options.sequence);
  const double fps = calibration.timing.empty() ? 30.0 : calibration.timing.front().fps;
  // The sequence's length: camera 0's frames.
  int frame_count = 0;
  while (fs::exists(options.sequence / "frames" / calibration.cameras.front().name / FrameFileName(frame_count, "png"))) {
    ++frame_count;
  }
  for (const CameraFault& fault : options.faults) {
    bool known = false;
    for (const Camera& cam : calibration.cameras) known = known || cam.name == fault.camera;
    if (!known) throw InputError((options.sequence / "calib/cameras.json").string(), "--fault", "no camera '" + fault.camera + "'");
    if (fault.from_s * fps >= frame_count) {
      throw InputError("", "--fault",
                       "starts at " + std::to_string(fault.from_s) + " s, after the sequence's " +
                           std::to_string(frame_count / fps) + " s");
    }
  }
  CheckOutputApart(options.out, {options.sequence}, "--out");
  StagingDir staging(options.out, options.overwrite, "--out", "fault");
  LinkTree(options.sequence, staging.path());
  nlohmann::json record = nlohmann::json::array();
  for (const CameraFault& fault : options.faults) {
    const int touched = ApplyFault(fault, staging.path(), fps, frame_count);
    record.push_back({{"camera", fault.camera},
                      {"kind", FaultKindName(fault.kind)},
                      {"from_s", fault.from_s},
                      {"to_s", fault.to_s},
                      {"frames", touched}});
    Log().info("fault: camera {} {} from {} s to {} s ({} frames)", fault.camera, FaultKindName(fault.kind),
               fault.from_s, fault.to_s, touched);
  }
  nlohmann::json j = {{"format", "irbench.faults/1"},
                      {"source", fs::absolute(options.sequence).lexically_normal().string()},
                      {"faults", record}};
  AtomicWriteFile(staging.path() / "faults.json", j.dump(2) + "\n");
  staging.Commit();
  return staging.final_path();
}

}  // namespace irbench
