// Scan sheets: each face's pixels give back the distances the geometry puts
// there (read through the TURBO colour map, not through the code drawing
// them), free and unvisited samples are marked, and `sandbox scan` writes one.

#include "app/scan_sheet.h"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "scene/collision_world.h"
#include "scene/level.h"
#include "sensors/face_scanner.h"
#include "tests/app/run_sandbox.h"
#include "tests/test_util.h"

namespace {

using namespace sandbox;

// The distance a colour stands for: the nearest entry of OpenCV's TURBO map
// over 0 .. half extent; -1 when no entry is near.
double DistanceOf(const cv::Vec3b& bgr, double half_extent_m) {
  cv::Mat ramp(1, 256, CV_8U), turbo;
  for (int i = 0; i < 256; ++i) ramp.at<std::uint8_t>(0, i) = std::uint8_t(i);
  cv::applyColorMap(ramp, turbo, cv::COLORMAP_TURBO);
  int best = -1, best_error = 1 << 30;
  for (int i = 0; i < 256; ++i) {
    const cv::Vec3b t = turbo.at<cv::Vec3b>(0, i);
    int error = 0;
    for (int k = 0; k < 3; ++k) error += (t[k] - bgr[k]) * (t[k] - bgr[k]);
    if (error < best_error) best_error = error, best = i;
  }
  return best_error <= 12 ? half_extent_m * best / 255.0 : -1.0;
}

// A wall across +x at x = 10 and a floor 7 m below the scanner.
scene::Level WallAndFloor(sandbox::testing::TempDir& dir) {
  dir.Write("wall.obj", "o wall\nv 10 -40 -40\nv 10 40 -40\nv 10 40 40\nv 10 -40 40\nf 1 2 3 4\n");
  dir.Write("floor.obj",
            "o floor\nv -40 -40 -7\nv 40 -40 -7\nv 40 40 -7\nv -40 40 -7\nf 1 2 3 4\n");
  return scene::LoadLevel(dir.Write("level.toml",
                                    "[[actor]]\nname = \"wall\"\nfile = \"wall.obj\"\n"
                                    "[[actor]]\nname = \"floor\"\nfile = \"floor.obj\"\n"));
}

TEST(ScanSheetTest, PixelsGiveBackTheDistancesOfTheWallAndTheFloor) {
  sandbox::testing::TempDir dir;
  const scene::Level level = WallAndFloor(dir);
  const scene::CollisionWorld world(level);
  sensors::RayCaster caster;
  sensors::FaceScannerConfig config;  // 51 x 51 a face, 1 m apart, 25 m half extent
  config.refresh = sensors::Refresh::kFull;
  config.alignment = sensors::Alignment::kWorld;
  const sensors::FaceScanner scanner(config);
  sensors::FaceScan scan = scanner.EmptyScan();
  scanner.Scan(world, caster, {}, Eigen::Isometry3d::Identity(), 0, &scan);

  const app::ScanSheet sheet = app::DrawFaceScanSheet(scan, 25.0, "test");
  const int n = scan.n, k = sheet.sample_px;
  ASSERT_EQ(sheet.panels[0].width, n * k);
  // Every sample's square centre, below the panel's label (the top 16 pixels).
  auto each_sample = [&](int face, auto&& check) {
    const cv::Rect& panel = sheet.panels[std::size_t(face)];
    for (int r = 0; r < n; ++r) {
      for (int c = 0; c < n; ++c) {
        const int x = panel.x + c * k + k / 2, y = panel.y + (n - 1 - r) * k + k / 2;
        if (y < panel.y + 16) continue;
        check(r, c, sheet.bgr.at<cv::Vec3b>(y, x));
      }
    }
  };
  int checked = 0;
  // +X: every ray meets the wall 10 m out; -Z: the floor 7 m down.
  for (const std::pair<int, double>& face_distance : {std::pair{0, 10.0}, std::pair{5, 7.0}}) {
    const int face = face_distance.first;  // not a structured binding: lambdas capture it
    const double expected = face_distance.second;
    each_sample(face, [&](int r, int c, const cv::Vec3b& bgr) {
      EXPECT_NEAR(DistanceOf(bgr, 25.0), expected, 25.0 / 255.0 * 1.01)
          << "face " << face << " row " << r << " column " << c;
      ++checked;
    });
  }
  EXPECT_GT(checked, 2 * 45 * 51);
  // +Z: nothing above within 25 m: white.
  each_sample(4, [&](int, int, const cv::Vec3b& bgr) { EXPECT_EQ(bgr, cv::Vec3b(255, 255, 255)); });

  // A six-stage scan at tick 0 has visited the +X face only: the others are grey.
  sensors::FaceScannerConfig staged = config;
  staged.refresh = sensors::Refresh::kSixStage;
  const sensors::FaceScanner six(staged);
  sensors::FaceScan partial = six.EmptyScan();
  six.Scan(world, caster, {}, Eigen::Isometry3d::Identity(), 0, &partial);
  const app::ScanSheet partial_sheet = app::DrawFaceScanSheet(partial, 25.0);
  const cv::Rect& minus_z = partial_sheet.panels[5];
  EXPECT_EQ(partial_sheet.bgr.at<cv::Vec3b>(minus_z.y + minus_z.height / 2,
                                            minus_z.x + minus_z.width / 2),
            cv::Vec3b(64, 64, 64));
  EXPECT_THROW(app::DrawFaceScanSheet(sensors::FaceScan{}, 25.0), std::invalid_argument);
}

TEST(ScanSheetTest, SandboxScanWritesTheSheet) {
  sandbox::testing::TempDir dir;
  WallAndFloor(dir);
  const std::string sheet = (dir.path() / "sheet.png").string();
  const auto run = sandbox::testing::RunSandbox("scan " + (dir.path() / "level.toml").string() +
                                                " --at 0,0,0 --aligned world --out " + sheet);
  ASSERT_EQ(run.exit_code, 0) << run.out;
  const cv::Mat image = cv::imread(sheet, cv::IMREAD_COLOR);
  ASSERT_FALSE(image.empty());
  // The middle of the +X panel (the unfolded cube's centre) is 10 m away.
  const int n = 51, k = std::max(1, 160 / n), gap = 6, top = 30;
  const cv::Point middle(gap + (n * k + gap) + n * k / 2, top + (n * k + gap) + n * k / 2);
  EXPECT_NEAR(DistanceOf(image.at<cv::Vec3b>(middle), 25.0), 10.0, 0.1);
  // A sheet is for face scans only.
  const auto lidar = sandbox::testing::RunSandbox("scan " + (dir.path() / "level.toml").string() +
                                                  " --at 0,0,0 --sensor lidar --out " + sheet);
  EXPECT_EQ(lidar.exit_code, 2);
  EXPECT_NE(lidar.out.find("face scans only"), std::string::npos) << lidar.out;
}

}  // namespace
