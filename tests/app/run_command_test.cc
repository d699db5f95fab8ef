// `sandbox run --out` as a user runs it: every camera of the sample level
// writes its frames at its own rate, each listed in its index, with depth
// where the manifest asks for it; bad options fail with a clear message.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include <opencv2/imgcodecs.hpp>

#include "tests/app/run_sandbox.h"
#include "tests/test_util.h"

namespace {

using sandbox::testing::RunSandbox;

struct IndexRow {
  long tick;
  double time_s;
  std::string file;
};

std::vector<IndexRow> ReadIndex(const std::filesystem::path& csv) {
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "tick,time_s,file,x,y,z,qw,qx,qy,qz") << csv;
  std::vector<IndexRow> rows;
  while (std::getline(in, line)) {
    std::stringstream cells(line);
    std::string tick, time, file;
    std::getline(cells, tick, ',');
    std::getline(cells, time, ',');
    std::getline(cells, file, ',');
    rows.push_back({std::stol(tick), std::stod(time), file});
  }
  return rows;
}

TEST(RunCommandTest, CamerasWriteIndexedFramesAtTheirRatesWithDepth) {
  sandbox::testing::TempDir dir;
  const double duration_s = 1.5;
  const auto run = RunSandbox("run --duration 1.5 --lcm-url memq:// --out " + dir.path().string());
  ASSERT_EQ(run.exit_code, 0) << run.out;
  std::smatch counts;
  ASSERT_TRUE(std::regex_search(
      run.out, counts, std::regex(R"(frames: (\d+) rendered, (\d+) written, (\d+) dropped, (\d+) failed)")))
      << run.out;
  const long rendered = std::stol(counts[1]), written = std::stol(counts[2]);
  EXPECT_EQ(std::stol(counts[4]), 0) << run.out;
  EXPECT_LE(written, rendered);
  EXPECT_GE(written, 5) << run.out;

  // The sample level's cameras: chase 640x480 at 30 Hz, belly 320x240 at 10 Hz with depth.
  struct Camera {
    const char* name;
    int width, height;
    double rate_hz;
    bool depth;
  };
  long indexed = 0;
  for (const Camera& camera : {Camera{"chase", 640, 480, 30.0, false},
                               Camera{"belly", 320, 240, 10.0, true}}) {
    const std::vector<IndexRow> rows = ReadIndex(dir.path() / (std::string(camera.name) + ".csv"));
    ASSERT_FALSE(rows.empty()) << camera.name;
    indexed += long(rows.size());
    EXPECT_LE(double(rows.size()), duration_s * camera.rate_hz + 2) << camera.name;
    for (std::size_t i = 0; i < rows.size(); ++i) {
      if (i > 0) {
        EXPECT_GT(rows[i].tick, rows[i - 1].tick) << camera.name;
      }
      const cv::Mat color = cv::imread((dir.path() / rows[i].file).string(), cv::IMREAD_UNCHANGED);
      ASSERT_FALSE(color.empty()) << rows[i].file;
      EXPECT_EQ(color.cols, camera.width);
      EXPECT_EQ(color.rows, camera.height);
      EXPECT_EQ(color.type(), CV_8UC3);
      const std::string stem = rows[i].file.substr(0, rows[i].file.size() - 4);
      const std::filesystem::path depth_file = dir.path() / (stem + "_depth.png");
      EXPECT_EQ(std::filesystem::exists(depth_file), camera.depth) << depth_file;
    }
    if (camera.depth) {
      // Pitched 60 degrees down from 60 m up: the ground fills most of the view.
      const cv::Mat depth = cv::imread(
          (dir.path() / (rows[0].file.substr(0, rows[0].file.size() - 4) + "_depth.png")).string(),
          cv::IMREAD_UNCHANGED);
      ASSERT_EQ(depth.type(), CV_16UC1);
      EXPECT_GT(cv::countNonZero(depth), depth.total() / 2);
    }
  }
  EXPECT_EQ(indexed, written);
}

TEST(RunCommandTest, BadFrameOptionsFailClearly) {
  sandbox::testing::TempDir dir;
  const auto gif =
      RunSandbox("run --duration 0.1 --lcm-url memq:// --frames gif --out " + dir.path().string());
  EXPECT_NE(gif.exit_code, 0);
  EXPECT_NE(gif.out.find("--frames must be jpg, png, mp4 or avi, got 'gif'"), std::string::npos)
      << gif.out;
  const auto tiff =
      RunSandbox("run --duration 0.1 --lcm-url memq:// --depth tiff --out " + dir.path().string());
  EXPECT_NE(tiff.exit_code, 0);
  EXPECT_NE(tiff.out.find("--depth must be png, npy or exr, got 'tiff'"), std::string::npos) << tiff.out;
  const std::string file = (dir.path() / "not_a_folder").string();
  std::ofstream(file) << "x";
  const auto blocked = RunSandbox("run --duration 0.1 --lcm-url memq:// --out " + file);
  EXPECT_EQ(blocked.exit_code, 1);
  EXPECT_NE(blocked.out.find("cannot create the output folder '" + file + "'"), std::string::npos)
      << blocked.out;
}

}  // namespace
