// `sandbox demo` end to end, as the README's first command runs it: the
// example model flies the wing as its own process over LCM inside a private
// network namespace (or in-process over memq://), and the frames, videos,
// indexes, scans and statistics appear; the status heartbeat reports the rate.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <regex>

#include "tests/app/run_sandbox.h"
#include "tests/test_util.h"

namespace {

using sandbox::testing::RunSandbox;
namespace fs = std::filesystem;

long Lines(const fs::path& file) {
  std::ifstream in(file);
  std::string line;
  long lines = 0;
  while (std::getline(in, line)) ++lines;
  return lines;
}

long Number(const std::string& text, const std::string& pattern) {
  std::smatch match;
  if (!std::regex_search(text, match, std::regex(pattern))) return -1;
  return std::stol(match[1]);
}

// What a demo of `seconds` leaves in `dir`. Counts of a real-time run depend
// on the machine: they are checked against bounds a machine ten times slower
// (or busier) still meets, and never above what the rates allow. What does
// not depend on speed is exact: every frame indexed, every indexed frame in
// its video, every scan whole.
void CheckDemoOutput(const std::string& out, const fs::path& dir, double seconds) {
  const long poses = Number(out, R"(ELAHA/POSE: (\d+) received)");
  EXPECT_GE(poses, long(seconds * 100 * 0.1)) << out;  // the model publishes at 100 Hz
  EXPECT_LE(poses, long(seconds * 100) + 10) << out;
  EXPECT_EQ(Number(out, R"(ELAHA/POSE: \d+ received, \d+ superseded, (\d+) rejected)"), 0) << out;
  const long heard = Number(out, R"(status heartbeat: (\d+) ELAHA/STATUS)");
  EXPECT_GE(heard, 1) << out;
  std::smatch rate;
  ASSERT_TRUE(std::regex_search(out, rate, std::regex(R"(last loop rate ([0-9.]+) Hz)"))) << out;
  EXPECT_GT(std::stod(rate[1]), 0.0) << out;
  EXPECT_LE(std::stod(rate[1]), 101.0) << out;
  // Ticks: one row each, at most 100 a second.
  const long ticks = Lines(dir / "ticks.csv") - 1;
  EXPECT_GE(ticks, long(seconds * 100 * 0.1));
  EXPECT_LE(ticks, long(seconds * 100) + 2);
  EXPECT_FALSE(cv::imread((dir / "ticks.png").string()).empty());
  EXPECT_FALSE(cv::imread((dir / "overview.jpg").string()).empty());
  // Each camera: its JPEGs as indexed, and a video with the same frames.
  for (const char* camera : {"chase", "trailing", "belly"}) {
    const long indexed = Lines(dir / (std::string(camera) + ".csv")) - 1;
    const double rate_hz = std::string(camera) == "belly" ? 10 : 30;
    EXPECT_GE(indexed, 1) << camera << "\n" << out;
    EXPECT_LE(indexed, long(seconds * rate_hz) + 2) << camera;
    long jpegs = 0;
    for (const auto& entry : fs::directory_iterator(dir / camera)) {  // a folder a camera
      const std::string name = entry.path().filename().string();
      jpegs += name.rfind(std::string(camera) + "_", 0) == 0 && entry.path().extension() == ".jpg";
    }
    EXPECT_EQ(jpegs, indexed) << camera;
    cv::VideoCapture video((dir / (std::string(camera) + ".mp4")).string());
    ASSERT_TRUE(video.isOpened()) << camera;
    long frames = 0;
    cv::Mat frame;
    while (video.read(frame)) ++frames;
    EXPECT_EQ(frames, indexed) << camera;
  }
  // Scans: one PLY a second, each with the faces scanned so far.
  long scans = 0;
  for (const auto& entry : fs::directory_iterator(dir / "scans")) {
    if (entry.path().extension() != ".ply") continue;  // the sheets beside them
    ++scans;
    std::ifstream ply(entry.path());
    std::string line;
    long vertices = 0;
    while (std::getline(ply, line) && line != "end_header") {
      if (line.rfind("element vertex ", 0) == 0) vertices = std::stol(line.substr(15));
    }
    EXPECT_GE(vertices, 51 * 51) << entry.path();  // at least one whole face
  }
  EXPECT_GE(scans, 1);
  EXPECT_LE(scans, long(seconds) + 1);
}

TEST(DemoTest, TheExampleModelFliesTheWingInANamespaceAndEverythingIsWritten) {
  sandbox::testing::TempDir dir;
  const auto run = RunSandbox("demo --duration 5 --out " + dir.path().string());
  ASSERT_EQ(run.exit_code, 0) << run.out;
  if (run.out.find("no private network namespace here") != std::string::npos) {
    GTEST_SKIP() << "no network namespace on this machine (the in-process test covers the rest)";
  }
  EXPECT_NE(run.out.find("flies the wing over LCM"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("LCM udpm://"), std::string::npos) << run.out;
  CheckDemoOutput(run.out, dir.path(), 5.0);
  std::ifstream log(dir.path() / "fly_wing.log");
  std::string line;
  std::getline(log, line);
  EXPECT_NE(line.find("fly_wing: published"), std::string::npos) << line;
}

TEST(DemoTest, InProcessTheModelFliesOverMemq) {
  sandbox::testing::TempDir dir;
  const auto run = RunSandbox("demo --in-process --duration 3 --out " + dir.path().string());
  ASSERT_EQ(run.exit_code, 0) << run.out;
  EXPECT_NE(run.out.find("LCM memq://"), std::string::npos) << run.out;
  CheckDemoOutput(run.out, dir.path(), 3.0);
}

TEST(DemoTest, BadArgumentsFailClearly) {
  const auto level = RunSandbox("demo some_level.toml");
  EXPECT_EQ(level.exit_code, 2);
  EXPECT_NE(level.out.find("takes no level"), std::string::npos) << level.out;
  const auto duration = RunSandbox("demo --duration -1");
  EXPECT_EQ(duration.exit_code, 2);
  EXPECT_NE(duration.out.find("--duration must be above 0 and at most 3600 s"), std::string::npos)
      << duration.out;
}

}  // namespace
