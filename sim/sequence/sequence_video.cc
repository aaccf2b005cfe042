#include "sim/sequence/sequence_video.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "common/error.h"
#include "sim/sequence/render_resume.h"

namespace irbench {
namespace fs = std::filesystem;
namespace {

// One video from `count` numbered PNG files of `folder`.
void EncodeFolder(const fs::path& folder, int count, const fs::path& video, double fps) {
  cv::VideoWriter writer;
  for (int i = 0; i < count; ++i) {
    const fs::path file = folder / FrameFileName(i, "png");
    const cv::Mat image = cv::imread(file.string(), cv::IMREAD_GRAYSCALE);
    if (image.empty()) throw InputError(file.string(), "", "unreadable frame while writing " + video.string());
    if (!writer.isOpened()) {
      fs::create_directories(video.parent_path());
      if (!writer.open(video.string(), cv::CAP_FFMPEG, cv::VideoWriter::fourcc('F', 'F', 'V', '1'), fps,
                       image.size(), false)) {
        throw RuntimeError("cannot write " + video.string() + ": OpenCV's FFmpeg writer has no FFV1");
      }
    }
    writer.write(image);
  }
}

}  // namespace

void WriteSequenceVideos(const fs::path& root,
                         const std::vector<std::string>& cameras,
                         int frames,
                         int backgrounds,
                         double fps) {
  for (const std::string& cam : cameras) {
    EncodeFolder(root / "frames" / cam, frames, root / "videos" / (cam + kVideoExtension), fps);
    if (backgrounds > 0) {
      EncodeFolder(root / "background" / cam, backgrounds, root / "background" / (cam + kVideoExtension), fps);
    }
  }
}

}  // namespace irbench
