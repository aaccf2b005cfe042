#pragma once
// 2D-3D ICP (thesis 6.2): project the 3D model into every image, fit each
// projected segment to the silhouette's polygon outline by a weighted 2D ICP,
// turn each 2D fit back into 3D and average across cameras.
//
//  - Model points: `points_per_segment` points on each segment's projected
//    ellipse with outward normals (Eq. 6.6), leaving out points inside another
//    segment's ellipse (they are not on the silhouette's outline).
//  - Closest points on the silhouette polygons' edges, ignoring edges whose
//    outward normal is more than pi/2 from the model point's (6.2.4), with
//    exponential weights exp(-d / weight_scale_px) (Eq. 6.7-6.9).
//  - A limb's 2D fit is a rotation about its joint's projection; back in 3D it
//    is a rotation about the joint's viewing ray (6.2.5, Fig. 6.5). The cameras'
//    rotations are averaged as sign-aligned quaternions (Eq. 6.10).
//  - The body's 2D fit (lower and upper body) is a translation; back in 3D a
//    displacement parallel to the image plane at the body's depth. Instead of
//    the thesis's plain average the cameras' displacements are combined by
//    least squares (each camera fixes only the components across its view
//    ray), which does not shrink the motion along any one camera's ray.
//  - Upper arms move first, then the model is re-projected and the forearms
//    follow, 2-3 iterations in all (the thesis: "2-3 iterations are
//    sufficient").

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "geometry/camera.h"
#include "tracker/body_model/body_model.h"

namespace irbench {

struct IcpOptions {
  int iterations = 2;
  int points_per_segment = 16;
  double weight_scale_px = 4.0;     // exponential weight scale (full-resolution pixels)
  double max_distance_px = 25.0;    // pairs farther apart are ignored
  double max_normal_angle_rad = M_PI / 2;
  // Combine the cameras' limb rotations by least squares (default) or by the
  // thesis's quaternion average (Eq. 6.10), which shrinks each camera's
  // in-plane rotation by the number of cameras.
  bool least_squares = true;
  void Check() const;  // throws InputError naming the field
};

// One camera's outline: closed polygons in ideal (undistorted) pixels, each
// vertex list in either orientation.
struct IcpView {
  Camera camera;
  Eigen::Matrix<double, 3, 4> projection;  // ProjectionMatrix(camera)
  std::vector<std::vector<Eigen::Vector2d>> polygons;
};

// Eq. 6.10: the normalised weighted sum of unit quaternions, each sign-flipped
// to agree with the first (q and -q are the same rotation). Empty weights:
// equal weights.
Eigen::Quaterniond AverageQuaternions(const std::vector<Eigen::Quaterniond>& quaternions,
                                      const std::vector<double>& weights = {});

// Refines `pose` towards the outlines. Returns the refined pose (joint limits
// applied).
BodyPose RefineIcp(const BodyShape& shape, const BodyPose& pose, const std::vector<IcpView>& views,
                   const IcpOptions& options);

}  // namespace irbench
