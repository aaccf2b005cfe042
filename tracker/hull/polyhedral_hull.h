#pragma once
// The polyhedral visual hull (thesis 4.1, steps 2-3, Fig. 4.2-4.3; after
// Matusik et al.'s polyhedral visual hulls). Every polygon edge E of view m
// and the camera centre C_m span a planar wedge on the boundary of view m's
// silhouette cone; the part of that wedge inside the cones of all other views
// is a patch of the hull surface. The union of the patches is the hull.
//
// Implementation: each wedge is swept by rays from C_m through points along E
// (every ray_step_px pixels, and E's end points, refined adaptively where the
// patch outline bends or an interval appears or vanishes). Each ray is cut exactly
// against every other view's polygon: the ray projects onto a line in that
// view's undistorted image plane; its crossings with the polygon edges are
// solved in closed form (a homogeneous line through two undistorted polygon
// vertices against the projected ray) and the pieces between crossings are
// kept when inside the polygon (even-odd). The intersection of the pieces over
// all views, clipped to the box, gives intervals on the ray; intervals of
// neighbouring rays that overlap are joined by two triangles. The faces are
// oriented outwards (away from the silhouette side of E). World frame:
// metres, z up.
//
// Not watertight: patches of different wedges meet without shared vertices,
// and where an interval appears or vanishes a sliver narrower than
// 2^-max_refinement of a ray step is left open. The volume by signed tetrahedra about the world
// origin is still close, since the gaps are small; the faces the box cuts off at the floor z = 0
// contribute nothing to it.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "geometry/camera.h"
#include "tracker/hull/polygon.h"

namespace irbench {

struct PolyhedralHullOptions {
  // Clip box, world metres (default: the stage volume).
  Eigen::Vector3d min_corner_m{-1.5, -1.5, 0.0};
  Eigen::Vector3d max_corner_m{1.5, 1.5, 2.2};
  // Spacing of the rays along each polygon edge, pixels of that view.
  double ray_step_px = 2.0;
  int max_rays_per_edge = 64;
  // Between two rays whose intervals differ in number, or whose half-way ray
  // ends off the straight chords by more than max_chord_error_m (metres), a
  // ray is inserted half way, at most max_refinement times.
  double max_chord_error_m = 0.002;
  int max_refinement = 10;
  // Points nearer than this to another camera's image plane (camera z,
  // metres) are not constrained by that camera.
  double near_m = 0.05;

  void Check() const;  // throws InputError naming the field
};

// A triangle mesh in world metres; triangles wind counter-clockwise seen from
// outside.
struct HullMesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::array<uint32_t, 3>> triangles;
  std::vector<int> triangle_view;  // the view whose polygon edge spans each face
};

// Volume enclosed by an outward-wound mesh, cubic metres: the sum of signed
// tetrahedra to the world origin (divergence theorem). Open parts at z = 0
// contribute nothing.
double MeshVolume(const HullMesh& mesh);

// Builds the polyhedral visual hull from one set of polygons per camera
// (`polygons[c]` for `cameras[c]`, pixel coordinates of that camera). A camera
// constrains only points in front of it that project inside its image. Returns
// nullopt when the hull is empty (no polygons, or the cones do not meet).
// Throws InputError on a count mismatch or bad options.
std::optional<HullMesh> PolyhedralVisualHull(const std::vector<Camera>& cameras,
                                             const std::vector<SilhouettePolygons>& polygons,
                                             const PolyhedralHullOptions& options = {});

}  // namespace irbench
