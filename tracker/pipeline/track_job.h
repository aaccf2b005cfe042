#pragma once
// `irbench track SEQ`: runs the front end (and, stage pose, the pose tracker)
// over a sequence and writes what it found.
//
//   <out>/track.jsonl              the tracker output (docs/architecture.md, "Tracker output"): state,
//                                  joints3d, the 21 dof, pointing rays with
//                                  screen hits (stage "pose", the default); with
//                                  --stage features only the state and the
//                                  root from the voxel hull
//   <out>/track.json               the run: every tracker setting by its key
//                                  (track_settings.h), the sequence, frames
//   <out>/features.jsonl           a line per frame: per camera the silhouette's
//                                  area, the light level, blobs removed; ms per stage
//   <out>/silhouettes/<cam>/NNNNNN.png   255 person, 0 else
//   <out>/overlays/<cam>/NNNNNN.png      (--overlays) the frame with the
//                                  silhouette outline (green), the pixels
//                                  shadow removal took away (red), axis points
//                                  by part, 3D axis points projected (white),
//                                  the tracked ellipsoid model (orange)
//   <out>/hull/NNNNNN_voxels.ply, NNNNNN_polyhedral.ply   (--ply) the voxel
//                                  hull as cubes and the polyhedral hull, world
//                                  metres, z up (MeshLab, Blender)
//   <out>/descriptors.npy          (--descriptors) every frame's shape
//                                  descriptor (thesis 4.3), float32, frames x
//                                  bins (r, theta, phi in C order; docs/recognition.md);
//                                  a row of zeros where the stage looks empty
//
// The output folder appears only when complete (StagingDir).

#include <filesystem>
#include <optional>
#include <string>

#include "tracker/io/sequence_input.h"
#include "tracker/pipeline/track_settings.h"

namespace irbench {

struct TrackJobOptions {
  std::filesystem::path sequence;
  SequenceInputOptions input;  // frame files or videos (tracker/io/sequence_input.h)
  std::filesystem::path out;  // default: <sequence>/track
  // What the tracker computes; bound to flags, suite keys and track.json by
  // TrackSettings() (tracker/pipeline/track_settings.h).
  TrackerSettings tracker;
  bool overlays = false;
  bool ply = false;
  bool descriptors = false;
  std::optional<int> frames;  // default: all
  bool overwrite = false;
};

// Returns the output folder. Throws InputError on bad options or input.
std::filesystem::path RunTrackJob(const TrackJobOptions& options);

}  // namespace irbench
