#pragma once
// `irbench track SEQ --stage features`: runs the front end over a sequence and
// writes what it found, for inspection and for the later stages.
//
//   <out>/track.jsonl              the tracker output (docs/formats.md): state,
//                                  joints3d, the 21 dof, pointing rays with
//                                  screen hits (stage "pose", the default); with
//                                  --stage features only the state and the
//                                  root from the voxel hull
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
//
// The output folder appears only when complete (StagingDir).

#include <filesystem>
#include <optional>
#include <string>

#include "tracker/frontend/frontend.h"

namespace irbench {

// What is wrong with a TrackJobOptions::shadow_edge_scale ("must be in
// 0.25..8"), or "" when it is in range: the track job and suites check it.
std::string ShadowEdgeScaleProblem(double scale);

struct TrackJobOptions {
  std::filesystem::path sequence;
  std::filesystem::path out;  // default: <sequence>/track
  std::string stage = "pose";  // or "features" (front end only)
  int particles = 100;         // pose: particles of the filter (thesis 6.3)
  uint64_t seed = 1;           // pose: the filter's random stream
  // pose: the rest-state SVM (irbench train rest); empty: the default model
  // (tracker/models/rest_svm.yml) when it exists, else rest stays null.
  std::filesystem::path rest_model;
  std::string background_model = "flicker";  // or "plain" (thesis 3.1)
  bool remove_shadows = true;
  // Shadow removal's Canny thresholds (ShadowOptions) times this: they are
  // set for the washed-out `thesis` images; images of more contrast with
  // soft shadows (the `clean` preset with --shadows on: 2) need them higher,
  // or the penumbra next to the feet passes as an edge (docs/tracker.md).
  double shadow_edge_scale = 1.0;  // 0.25..8 (ShadowEdgeScaleProblem)
  bool overlays = false;
  bool ply = false;
  int hull_missing_views = 0;  // voxel hull: cameras allowed to disagree (0: the thesis's hull; 1)
  std::optional<int> frames;  // default: all
  bool overwrite = false;
};

// Returns the output folder. Throws InputError on bad options or input.
std::filesystem::path RunTrackJob(const TrackJobOptions& options);

}  // namespace irbench
