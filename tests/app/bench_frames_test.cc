// `sandbox bench-frames` as a user runs it: the look and images it is asked
// for, every frame in its CSV, and clear errors for a bad look or kind.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "tests/app/run_sandbox.h"
#include "tests/test_util.h"

namespace {

using sandbox::testing::RunSandbox;

TEST(BenchFramesTest, RunsTheLookAndImagesAskedForAndWritesEveryFrame) {
  sandbox::testing::TempDir dir;
  const auto run = RunSandbox(
      "bench-frames --frames 3 --runs 1 --quality high --kind "
      "color,segmentation --out " +
      dir.path().string());
  ASSERT_EQ(run.exit_code, 0) << run.out;
  EXPECT_NE(run.out.find("high look, color,segmentation"), std::string::npos) << run.out;
  // 2 levels x 3 cases x 3 frames, after the header.
  std::ifstream csv(dir.path() / "frames.csv");
  int rows = 0;
  for (std::string line; std::getline(csv, line);) ++rows;
  EXPECT_EQ(rows, 1 + 2 * 3 * 3);
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "sample_overlay.png"));
}

TEST(BenchFramesTest, BadLookOrKindIsOneClearMessage) {
  sandbox::testing::TempDir dir;
  const std::string out = " --out " + dir.path().string();
  auto run = RunSandbox("bench-frames --kind colour" + out);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_EQ(run.out,
            "sandbox bench-frames: unknown image kind 'colour' (color, depth, segmentation or "
            "normals)\n");
  run = RunSandbox("bench-frames --quality ultra" + out);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_EQ(run.out,
            "sandbox bench-frames: quality must be \"fast\" or \"high\" (or \"plain\"), got "
            "'ultra'\n");
}

}  // namespace
