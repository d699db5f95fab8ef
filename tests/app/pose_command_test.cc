// `sandbox pose` as a user runs it: the posed mesh and bone frames it writes.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <fstream>
#include <sstream>

#include "tests/app/run_sandbox.h"
#include "tests/test_util.h"

namespace {

using sandbox::testing::RunSandbox;

std::string Robots() { return std::string(SANDBOX_SOURCE_DIR) + "/assets/robots/robots.toml"; }

// The CSV row of bone `name`: x, y, z, qw, qx, qy, qz.
std::vector<double> BoneRow(const std::string& csv_file, const std::string& name) {
  std::ifstream in(csv_file);
  std::string line;
  while (std::getline(in, line)) {
    std::stringstream row(line);
    std::string index, bone, cell;
    std::getline(row, index, ',');
    std::getline(row, bone, ',');
    if (bone != name) continue;
    std::vector<double> values;
    while (std::getline(row, cell, ',')) values.push_back(std::stod(cell));
    return values;
  }
  return {};
}

TEST(PoseCommandTest, ArmJointsGiveTheHandComputedFrames) {
  sandbox::testing::TempDir dir;
  const std::string ply = (dir.path() / "arm.ply").string();
  const auto run = RunSandbox("pose " + Robots() + " --robot ARM --robot-pose 1,2,3,0,0,90 " +
                              "--bones 'link1 30; link2 -45; 3 60' --out " + ply);
  ASSERT_EQ(run.exit_code, 0) << run.out;
  // Base at (1, 2, 3) turned 90 degrees about z; joints 0.25, 0.2, 0.6 up;
  // link1 about z by 30, link2 about y by -45, link3 about y by 60 (degrees).
  const double d = 3.14159265358979323846 / 180.0;
  const Eigen::Isometry3d X =
      Eigen::Translation3d(1, 2, 3) * Eigen::AngleAxisd(90 * d, Eigen::Vector3d::UnitZ()) *
      Eigen::Translation3d(0, 0, 0.25) * Eigen::AngleAxisd(30 * d, Eigen::Vector3d::UnitZ()) *
      Eigen::Translation3d(0, 0, 0.2) * Eigen::AngleAxisd(-45 * d, Eigen::Vector3d::UnitY()) *
      Eigen::Translation3d(0, 0, 0.6) * Eigen::AngleAxisd(60 * d, Eigen::Vector3d::UnitY());
  const std::vector<double> row = BoneRow(dir.path() / "arm.bones.csv", "link3");
  ASSERT_EQ(row.size(), 7u);
  EXPECT_LT((Eigen::Vector3d(row[0], row[1], row[2]) - X.translation()).norm(), 1e-5);
  const Eigen::Quaterniond q(row[3], row[4], row[5], row[6]);
  EXPECT_LT(q.angularDistance(Eigen::Quaterniond(X.linear())), 1e-5);

  // The PLY: a header naming 168 vertices and 84 triangles (7 boxes), then the data.
  std::ifstream in(ply);
  std::ostringstream contents;
  contents << in.rdbuf();
  const std::string text = contents.str();
  EXPECT_NE(text.find("element vertex 168\n"), std::string::npos);
  EXPECT_NE(text.find("element face 84\n"), std::string::npos);
  const std::size_t lines = static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
  const std::size_t header = 13;
  EXPECT_EQ(lines, header + 168 + 84);
}

TEST(PoseCommandTest, BadBonesAreOneClearMessage) {
  sandbox::testing::TempDir dir;
  const std::string out = " --out " + (dir.path() / "x.ply").string();
  auto run = RunSandbox("pose " + Robots() + " --robot ARM --bones 'elbow 10'" + out);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_EQ(run.out, "sandbox pose: --bones: robot 'ARM' has no bone 'elbow' (7 bones)\n");
  run = RunSandbox("pose " + Robots() + " --robot ARM --bones 'link2 10 20'" + out);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_EQ(run.out,
            "sandbox pose: --bones: bone 'link2' takes 1 values (angles in degrees), got 2\n");
  run = RunSandbox("pose " + Robots() + " --robot NOBODY" + out);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_EQ(run.out, "sandbox pose: the level has no robot 'NOBODY'\n");
  EXPECT_EQ(RunSandbox("pose " + Robots()).exit_code, 2);  // no --out
}

}  // namespace
