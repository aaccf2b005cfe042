#pragma once
// `irbench render --video`: a sequence's frames as one lossless video per
// camera (FFV1 in Matroska, 8-bit grey), beside the PNG files, so that a
// recording-shaped copy can be tracked (tracker/io/sequence_input.h) and
// played in any video player.

#include <filesystem>
#include <string>
#include <vector>

namespace irbench {

// The video file names a sequence's `--video` render writes.
inline constexpr char kVideoExtension[] = ".mkv";

// Encodes frames/<cam>/NNNNNN.png (`frames` of them) into videos/<cam>.mkv and
// background/<cam>/NNNNNN.png (`backgrounds`) into background/<cam>.mkv under
// `root`, at `fps`. Throws RuntimeError when OpenCV's FFmpeg writer cannot
// write FFV1, InputError for a frame file that cannot be read.
void WriteSequenceVideos(const std::filesystem::path& root,
                         const std::vector<std::string>& cameras,
                         int frames,
                         int backgrounds,
                         double fps);

}  // namespace irbench
