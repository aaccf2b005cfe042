// EMVA 1288 photon transfer through the whole render path: a flat emissive
// wall filling a rig camera's view is rendered by the GL renderer, then exposed
// by the sensor model at 12 exposure times as frame pairs; the system gain
// and dark noise come back from the measured frames alone.

#include <gtest/gtest.h>


#include "sim/camera/rig.h"
#include "sim/render/renderer.h"
#include "sim/sensor/emva1288.h"

namespace irbench {
namespace {

TEST(PhotonTransferTest, RenderedFlatFieldsRecoverGainAndDarkNoise) {
  const Camera cam = LoadRig(std::string(IRBENCH_SOURCE_DIR) + "/rigs/theater4.json").cameras.at(0);
  auto context = CreateGlContext(GlBackend::kAuto);
  Renderer renderer(*context, {cam}, RenderOptions{});
  // An emissive wall of radiance 1 one metre in front of the camera, far
  // wider than the view.
  const Eigen::Isometry3d world_from_cam = cam.cam_from_world.inverse();
  TriangleMesh wall;
  AppendQuad(wall, world_from_cam * Eigen::Vector3d(-5, -5, 1), world_from_cam.linear() * Eigen::Vector3d(10, 0, 0),
             world_from_cam.linear() * Eigen::Vector3d(0, 10, 0), Material{1.0f, 1.0f});
  renderer.SetStaticMesh(wall);
  CameraImages bright_image, dark_image;
  renderer.Render(0, &bright_image, false);
  renderer.SetStaticMesh(TriangleMesh{});
  renderer.Render(0, &dark_image, false);
  cv::Mat bright, dark;
  bright_image.grey.convertTo(bright, CV_32F, 1.0 / 255);
  dark_image.grey.convertTo(dark, CV_32F, 1.0 / 255);
  ASSERT_EQ(cv::mean(bright)[0], 1.0);
  ASSERT_EQ(cv::mean(dark)[0], 0.0);

  SensorParams p;
  p.photons_per_ms = 2000;
  p.quantum_efficiency = 0.5;
  p.full_well_e = 6000;
  p.system_gain_dn_per_e = 0.5;
  p.dark_noise_e = 8;
  p.dark_current_e_per_s = 0;
  p.bit_depth = 12;
  p.black_level_dn = 64;
  const SensorModel sensor(p, 9, cam.name, cam.width, cam.height);
  std::vector<double> exposures_ms;
  for (int level = 0; level < 12; ++level) exposures_ms.push_back(0.25 + 0.4 * level);
  const PhotonTransfer ptc = MeasurePhotonTransfer(sensor, bright, dark, exposures_ms, 0);
  const double gain = ptc.gain_dn_per_e;
  const double dark_noise = ptc.dark_noise_e;
  EXPECT_NEAR(gain, p.system_gain_dn_per_e, 0.03 * p.system_gain_dn_per_e);
  EXPECT_NEAR(dark_noise, p.dark_noise_e, 0.05 * p.dark_noise_e);
  std::printf("rendered photon transfer: K %.4f (%.4f) DN/e-, dark noise %.2f (%.2f) e-\n", gain,
              p.system_gain_dn_per_e, dark_noise, p.dark_noise_e);
}

}  // namespace
}  // namespace irbench
