// sandbox render's robot options: --robot-at under a fixed camera and
// --bone-values, seen in the segmentation image it writes.
#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <sstream>

#include "tests/app/run_sandbox.h"
#include "tests/test_util.h"

namespace {

using sandbox::testing::RunSandbox;

// The robot's pixels in a segmentation image and its legend (ids named "ELAHA/...").
int RobotPixels(const std::filesystem::path& png) {
  std::filesystem::path legend = png;
  legend.replace_filename(png.stem().string() + "_seg.csv");
  std::ifstream in(legend);
  std::set<int> ids;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    std::string id, kind, name;
    std::getline(fields, id, ',');
    std::getline(fields, kind, ',');
    std::getline(fields, name);
    if (name.rfind("ELAHA/", 0) == 0) ids.insert(std::stoi(id));
  }
  const cv::Mat image = cv::imread(png.string(), cv::IMREAD_UNCHANGED);
  EXPECT_EQ(image.type(), CV_16UC1) << png;
  int count = 0;
  for (int r = 0; r < image.rows; ++r)
    for (int c = 0; c < image.cols; ++c) count += ids.count(image.at<std::uint16_t>(r, c)) > 0;
  return count;
}

std::string Render(const sandbox::testing::TempDir& dir, const std::string& name,
                   const std::string& robot) {
  // 20 m above the wing's place, looking straight down.
  const std::string out = (dir.path() / (name + ".png")).string();
  const auto run = RunSandbox("render --camera fixed --at 0,0,80,0,90,0 --kind segmentation "
                              "--width 320 --height 240 " + robot + " --out " + out);
  EXPECT_EQ(run.exit_code, 0) << run.out;
  return out;
}

TEST(RenderCommandTest, TheRobotIsDrawnWhereRobotAtPutsItWithItsBoneValues) {
  sandbox::testing::TempDir dir;
  const int here = RobotPixels(Render(dir, "here", "--robot-at 0,0,60"));
  const int away = RobotPixels(Render(dir, "away", "--robot-at 300,0,60"));
  EXPECT_GT(here, 1000);
  EXPECT_EQ(away, 0);
  // Both wings' roots rolled up by 1.2 rad (bone values: root 2, then R1's
  // two angles at 2-3, ..., L1's at 22-23): less wing seen from above.
  std::string values;
  for (int i = 0; i < 45; ++i) {
    values += (i ? "," : "") + std::string(i == 2 ? "1.2" : i == 22 ? "-1.2" : "0");
  }
  const int bent = RobotPixels(Render(dir, "bent", "--robot-at 0,0,60 --bone-values " + values));
  EXPECT_LT(bent, here * 3 / 4) << here;
  EXPECT_GT(bent, here / 10);
}

TEST(RenderCommandTest, RobotAtAndBoneValuesAreChecked) {
  sandbox::testing::TempDir dir;
  const std::string out = " --out " + (dir.path() / "x.png").string();
  auto run = RunSandbox("render --camera fixed --at 0,0,100 --bone-values 1,2,3" + out);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.out.find("--bone-values: robot 'ELAHA' takes 45 values, got 3"), std::string::npos)
      << run.out;
  run = RunSandbox("render --camera chase --at 0,0,60 --robot-at 0,0,60" + out);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.out.find("--robot-at is for a fixed camera"), std::string::npos) << run.out;
  run = RunSandbox("render --camera fixed --at 0,0,100 --robot-at 0,0,nan" + out);
  EXPECT_EQ(run.exit_code, 2) << run.out;
}

}  // namespace
