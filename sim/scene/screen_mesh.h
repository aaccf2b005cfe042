#pragma once
// A projection screen as the sim renders it: its surface (geometry/screen.h)
// tessellated into the scene's mesh with a material.

#include "geometry/screen.h"
#include "sim/scene/mesh.h"

namespace irbench {

// Appends the screen's front face to `mesh` (a plane as a 4 x 2 quad grid, a
// cylinder as 64 segments), every vertex carrying `material`.
void AppendScreenGeometry(const ScreenSurface& screen,
                          const Material& material,
                          TriangleMesh& mesh);

}  // namespace irbench
