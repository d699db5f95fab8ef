// `sandbox run --out` as a user runs it: every camera of the sample level
// writes its frames at its own rate, each listed in its index, with depth
// where the manifest asks for it; bad options fail with a clear message.

#include "app/run_command.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <regex>
#include <sstream>
#include <thread>

#include "app/run_hooks.h"
#include "assets/generators/sample_terrain.h"
#include "scene/level.h"
#include "tests/app/flight_log.h"
#include "tests/app/run_sandbox.h"
#include "tests/test_util.h"

namespace {

using sandbox::testing::RunSandbox;

struct IndexRow {
  long tick;
  double time_s;
  std::string file;
  Eigen::Isometry3d X_WB, X_WC;  // robot and camera poses
  double fx, fy, cx, cy;
};

Eigen::Isometry3d Pose(const std::vector<double>& v, std::size_t at) {  // x y z qw qx qy qz
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translation() = Eigen::Vector3d(v[at], v[at + 1], v[at + 2]);
  X.linear() = Eigen::Quaterniond(v[at + 3], v[at + 4], v[at + 5], v[at + 6]).toRotationMatrix();
  return X;
}

std::vector<IndexRow> ReadIndex(const std::filesystem::path& csv) {
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line,
            "tick,time_s,file,x,y,z,qw,qx,qy,qz,cam_x,cam_y,cam_z,cam_qw,cam_qx,cam_qy,cam_qz,"
            "fx,fy,cx,cy,depth_file,segmentation_file,normals_file,lens,k1,k2,k3,k4,p1,p2")
      << csv;
  std::vector<IndexRow> rows;
  while (std::getline(in, line)) {
    std::stringstream cells(line);
    std::string tick, time, file, cell;
    std::getline(cells, tick, ',');
    std::getline(cells, time, ',');
    std::getline(cells, file, ',');
    std::vector<double> v;
    std::vector<std::string> image_files;  // depth, segmentation, normals ("" when none)
    while (v.size() < 18u && std::getline(cells, cell, ',')) v.push_back(std::stod(cell));
    for (int k = 0; k < 3 && std::getline(cells, cell, ','); ++k) image_files.push_back(cell);
    std::string lens;  // then the lens: a pinhole's, all coefficients 0
    std::getline(cells, lens, ',');
    EXPECT_EQ(lens, "pinhole") << line;
    int zeros = 0;
    while (std::getline(cells, cell, ',')) zeros += std::stod(cell) == 0.0;
    EXPECT_EQ(zeros, 6) << line;
    EXPECT_EQ(v.size(), 18u) << line;
    EXPECT_EQ(image_files.size(), 3u) << line;
    if (v.size() != 18u) break;
    rows.push_back({std::stol(tick), std::stod(time), file, Pose(v, 0), Pose(v, 7), v[14], v[15],
                    v[16], v[17]});
  }
  return rows;
}

// A replayed flight in lock-step: the cameras are due by input time and no
// frame is dropped, so every count is exact whatever the machine's speed.
TEST(RunCommandTest, CamerasWriteIndexedFramesAtTheirRatesWithDepth) {
  sandbox::testing::TempDir dir;
  const std::string log = (dir.path() / "flight.lcmlog").string();
  sandbox::testing::WriteFlightLog(log, 75);  // 50 Hz: 1.48 s of input time
  const double last_s = 74 * 0.02;
  const auto run = RunSandbox("run --replay " + log + " --out " + (dir.path() / "out").string());
  ASSERT_EQ(run.exit_code, 0) << run.out;
  std::smatch counts;
  ASSERT_TRUE(std::regex_search(
      run.out, counts,
      std::regex(R"(frames: (\d+) rendered, (\d+) written, (\d+) dropped, (\d+) failed)")))
      << run.out;
  const long rendered = std::stol(counts[1]), written = std::stol(counts[2]);
  EXPECT_EQ(std::stol(counts[3]), 0) << run.out;  // lock-step is lossless
  EXPECT_EQ(std::stol(counts[4]), 0) << run.out;
  EXPECT_EQ(written, rendered);

  // The sample level's cameras: chase and trailing 640x480 at 30 Hz, belly 320x240 at 10 Hz
  // with depth. A camera's frame k is due at k / rate: the first tick at or after it.
  struct Camera {
    const char* name;
    int width, height;
    double rate_hz;
    bool depth;
  };
  long indexed = 0;
  for (const Camera& camera :
       {Camera{"chase", 640, 480, 30.0, false}, Camera{"trailing", 640, 480, 30.0, false},
        Camera{"belly", 320, 240, 10.0, true}}) {
    const std::vector<IndexRow> rows =
        ReadIndex(dir.path() / "out" / (std::string(camera.name) + ".csv"));
    indexed += long(rows.size());
    EXPECT_EQ(long(rows.size()), long(std::floor(last_s * camera.rate_hz)) + 1) << camera.name;
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const double due_s = double(i) / camera.rate_hz;
      EXPECT_GE(rows[i].time_s, due_s - 1e-9) << camera.name << " frame " << i;
      EXPECT_LT(rows[i].time_s, due_s + 0.02 - 1e-9) << camera.name << " frame " << i;
      EXPECT_EQ(rows[i].tick, std::lround(rows[i].time_s / 0.02)) << camera.name;
      const cv::Mat color =
          cv::imread((dir.path() / "out" / rows[i].file).string(), cv::IMREAD_UNCHANGED);
      ASSERT_FALSE(color.empty()) << rows[i].file;
      EXPECT_EQ(color.cols, camera.width);
      EXPECT_EQ(color.rows, camera.height);
      EXPECT_EQ(color.type(), CV_8UC3);
      const std::string stem = rows[i].file.substr(0, rows[i].file.size() - 4);
      const std::filesystem::path depth_file = dir.path() / "out" / (stem + "_depth.png");
      EXPECT_EQ(std::filesystem::exists(depth_file), camera.depth) << depth_file;
    }
    if (camera.depth) {
      // Pitched 60 degrees down from 60 m up: the ground fills most of the view.
      const cv::Mat depth = cv::imread(
          (dir.path() / "out" / (rows[0].file.substr(0, rows[0].file.size() - 4) + "_depth.png"))
              .string(),
          cv::IMREAD_UNCHANGED);
      ASSERT_EQ(depth.type(), CV_16UC1);
      EXPECT_GT(cv::countNonZero(depth), depth.total() / 2);
    }
  }
  EXPECT_EQ(indexed, written);
}

TEST(RunCommandTest, PayloadDepthBackProjectsOntoTheTerrainThroughTheIndexedPoseAndIntrinsics) {
  sandbox::testing::TempDir dir;
  const std::string log = (dir.path() / "hover.lcmlog").string();
  sandbox::testing::WriteFlightLog(log, 3, 20'000, 0.0);  // over the origin, 60 m up
  const auto run =
      RunSandbox("run --replay " + log + " --frames png --out " + (dir.path() / "out").string());
  ASSERT_EQ(run.exit_code, 0) << run.out;
  const std::vector<IndexRow> rows = ReadIndex(dir.path() / "out" / "belly.csv");
  ASSERT_FALSE(rows.empty());
  const IndexRow& row = rows[0];
  // The belly camera: 320 x 240, 70 degrees vertically.
  EXPECT_NEAR(row.fy, 120.0 / std::tan(35.0 * M_PI / 180.0), 1e-6);
  EXPECT_EQ(row.fx, row.fy);
  EXPECT_EQ(row.cx, 159.5);
  EXPECT_EQ(row.cy, 119.5);
  // Pitched 60 degrees down on the body (the robot level).
  EXPECT_TRUE(row.X_WC.translation().isApprox(row.X_WB.translation(), 1e-9));
  EXPECT_NEAR((row.X_WC.linear() * Eigen::Vector3d::UnitX()).z(), -std::sin(M_PI / 3), 1e-6);
  const cv::Mat depth = cv::imread(
      (dir.path() / "out" / (row.file.substr(0, row.file.size() - 4) + "_depth.png")).string(),
      cv::IMREAD_UNCHANGED);
  ASSERT_EQ(depth.type(), CV_16UC1);
  // Every sampled pixel's point lies on the terrain or the lake's water (z = 6 m),
  // whichever is higher: the analytic surface, not the renderer's or the caster's.
  // Points within the boxes of the compact objects (wall, tower, boulder, gate)
  // are left out; the scattered rocks may take a few.
  const sandbox::scene::Level level = sandbox::scene::LoadLevel(sandbox::testing::SampleLevel());
  auto on_an_object = [&](const Eigen::Vector3d& p_W) {
    for (const sandbox::scene::Actor& actor : level.actors) {
      Eigen::AlignedBox3d box = actor.bounds_W;
      if (box.sizes().head<2>().maxCoeff() > 50.0) continue;  // terrain, water, rocks
      box.extend(box.min() - Eigen::Vector3d::Constant(0.1))
          .extend(box.max() + Eigen::Vector3d::Constant(0.1));
      if (box.contains(p_W)) return true;
    }
    return false;
  };
  int on_surface = 0, sampled = 0;
  for (int v = 5; v < depth.rows; v += 23) {
    for (int u = 5; u < depth.cols; u += 29) {
      const double d = depth.at<std::uint16_t>(v, u) * 1e-3;
      if (d == 0) continue;
      const Eigen::Vector3d p_C(d, -(u - row.cx) / row.fx * d, -(v - row.cy) / row.fy * d);
      const Eigen::Vector3d p_W = row.X_WC * p_C;
      if (on_an_object(p_W)) continue;
      const double surface = std::max(sandbox::assets::sample::TerrainHeight(p_W.x(), p_W.y()),
                                      sandbox::assets::sample::kWaterLevel_m);
      ++sampled;
      on_surface += std::abs(p_W.z() - surface) < 0.03;
    }
  }
  EXPECT_GT(sampled, 80);
  EXPECT_GE(on_surface, sampled * 97 / 100) << on_surface << " of " << sampled;
}

// The loop's pacing in real time; the exact rules (a late tick is followed at
// once, no burst to catch up) are TickPacerTest's. What holds on any machine:
// the slowed ticks last at least their stall and overrun, and the summary,
// ticks.csv and the plot agree. The loop runs in this process, slowed by a hook.
TEST(RunCommandTest, SlowTicksOverrunAndTheStatisticsAgreeWithTheSummary) {
  sandbox::testing::TempDir dir;
  // Ticks 50-52 take 40 ms each: four periods.
  sandbox::app::RunHooks hooks;
  hooks.end_of_tick = [](std::int64_t tick) {
    if (tick >= 50 && tick <= 52) std::this_thread::sleep_for(std::chrono::milliseconds(40));
  };
  std::ostringstream out, err;
  sandbox::testing::CommandRun run;
  run.exit_code = sandbox::app::RunLoop({"--duration", "1.5", "--lcm-url", "memq://", "--frames",
                                         "none", "--out", dir.path().string()},
                                        out, err, hooks);
  run.out = out.str() + err.str();
  ASSERT_EQ(run.exit_code, 0) << run.out;
  std::ifstream csv(dir.path() / "ticks.csv");
  std::string line;
  std::getline(csv, line);
  ASSERT_EQ(line, "tick,start_s,duration_ms,lateness_ms,inputs,rays,frames");
  std::vector<double> start, duration;
  std::vector<long> rays;
  while (std::getline(csv, line)) {
    std::stringstream cells(line);
    std::string cell[7];
    for (std::string& c : cell) std::getline(cells, c, ',');
    ASSERT_EQ(std::stol(cell[0]), long(start.size()));
    start.push_back(std::stod(cell[1]));
    duration.push_back(std::stod(cell[2]));
    rays.push_back(std::stol(cell[5]));
  }
  // A 10x slower machine still ticks 15 times in 1.5 s; ticks are 10 ms apart at least.
  ASSERT_GT(start.size(), 53u);
  EXPECT_LE(start.size(), 151u);
  for (int i = 50; i <= 52; ++i) EXPECT_GE(duration[std::size_t(i)], 40.0) << i;
  for (std::size_t i = 1; i < start.size(); ++i) {
    EXPECT_GE(start[i], start[i - 1] + duration[i - 1] / 1e3 - 1e-6) << "tick " << i;
  }
  // The summary agrees with the file: the longest tick and the overruns.
  const double longest = *std::max_element(duration.begin(), duration.end());
  std::smatch max;
  ASSERT_TRUE(std::regex_search(
      run.out, max,
      std::regex(R"(tick duration: p50 [0-9.]+ ms, p99 [0-9.]+ ms, max ([0-9.]+) ms)")))
      << run.out;
  EXPECT_NEAR(std::stod(max[1]), longest, 2e-3);
  EXPECT_NE(run.out.find(std::to_string(start.size()) + " ticks in"), std::string::npos) << run.out;
  std::smatch overruns;
  ASSERT_TRUE(std::regex_search(run.out, overruns, std::regex(R"((\d+) overruns)"))) << run.out;
  EXPECT_GE(std::stol(overruns[1]), 3);
  // The six-stage face scanner (51 x 51 a face) casts 2601 rays a tick, the range sensor
  // one at 50 Hz.
  EXPECT_GE(rays[10], 2601);
  EXPECT_LE(rays[10], 2602);
  const cv::Mat plot = cv::imread((dir.path() / "ticks.png").string());
  EXPECT_EQ(plot.cols, 1000);
  EXPECT_EQ(plot.rows, 500);
}

// SIGINT (Ctrl-C) or SIGTERM once a few frames are written: the run stops
// cleanly, the video holds every indexed frame, ticks.csv is complete.
void CheckStopsCleanlyOn(const std::string& signal) {
  sandbox::testing::TempDir dir;
  const std::string out = dir.path().string();
  const auto run = sandbox::testing::RunCommand(
      std::string(SANDBOX_BINARY) + " run --lcm-url memq:// --frames jpg,mp4 --out " + out +
      " & pid=$!; for i in $(seq 1200); do [ $(ls " + out +
      "/chase 2> /dev/null | grep -c '^chase_.*jpg$') -ge 3 ] && break; sleep 0.05; done; "
      "[ $i -lt 1200 ] || echo 'no third chase frame in " + out + "/chase'; kill -" + signal +
      " $pid; wait $pid");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  EXPECT_EQ(run.out.find("no third chase frame"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find(" ticks in "), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("statistics: "), std::string::npos) << run.out;
  const long indexed = long(ReadIndex(dir.path() / "chase.csv").size());
  EXPECT_GE(indexed, 3);
  cv::VideoCapture video((dir.path() / "chase.mp4").string());
  ASSERT_TRUE(video.isOpened());
  long frames = 0;
  for (cv::Mat frame; video.read(frame);) ++frames;
  EXPECT_EQ(frames, indexed);  // a finalised video holds every indexed frame
  std::ifstream ticks(dir.path() / "ticks.csv");
  long rows = -1;
  std::string line, last;
  while (std::getline(ticks, line)) ++rows, last = line;
  EXPECT_GE(rows, 1);
  EXPECT_EQ(std::count(last.begin(), last.end(), ','), 6) << "a cut row: " << last;
  std::smatch ticked;
  ASSERT_TRUE(std::regex_search(run.out, ticked, std::regex(R"(sandbox run: (\d+) ticks in)")));
  EXPECT_EQ(std::stol(ticked[1]), rows);
}

TEST(RunCommandTest, CtrlCFinishesVideosIndexesAndTheSummary) { CheckStopsCleanlyOn("INT"); }

TEST(RunCommandTest, SigtermFinishesVideosIndexesAndTheSummary) { CheckStopsCleanlyOn("TERM"); }

// A recording that cannot be written is reported at once and in the summary,
// and the run says output was lost (exit 3); a FIFO is refused for the log
// and for the replay, whose open would block.
TEST(RunCommandTest, ARecordingThatCannotBeWrittenIsReported) {
  const auto full = RunSandbox("run --duration 0.5 --lcm-url memq:// --record /dev/full");
  EXPECT_EQ(full.exit_code, 3) << full.out;
  EXPECT_NE(full.out.find("sandbox run: recording stopped: cannot write '/dev/full' after "),
            std::string::npos)
      << full.out;
  EXPECT_NE(full.out.find("No space left on device"), std::string::npos) << full.out;
  EXPECT_NE(full.out.find("(INCOMPLETE: cannot write '/dev/full'"), std::string::npos) << full.out;
  sandbox::testing::TempDir dir;
  const std::string fifo = (dir.path() / "pipe").string();
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  const auto record = RunSandbox("run --duration 0.1 --lcm-url memq:// --record " + fifo);
  EXPECT_EQ(record.exit_code, 1) << record.out;
  EXPECT_NE(record.out.find("cannot write the log '" + fifo + "': not a regular file"),
            std::string::npos)
      << record.out;
  const auto replay = RunSandbox("run --replay " + fifo);
  EXPECT_EQ(replay.exit_code, 1) << replay.out;
  EXPECT_NE(
      replay.out.find("cannot read the LCM log '" + fifo + "': is a FIFO, not a regular file"),
      std::string::npos)
      << replay.out;
  // /dev/null takes a recording.
  EXPECT_EQ(RunSandbox("run --duration 0.1 --lcm-url memq:// --record /dev/null").exit_code, 0);
}

// Waits end at the end of --duration or on a signal, however long the period.
TEST(RunCommandTest, AnyWaitEndsAtTheDurationOrOnASignal) {
  const auto slow = RunSandbox("run --rate 0.01 --duration 1 --lcm-url memq://");
  ASSERT_EQ(slow.exit_code, 0) << slow.out;
  std::smatch elapsed;
  ASSERT_TRUE(
      std::regex_search(slow.out, elapsed, std::regex(R"(sandbox run: 1 ticks in ([0-9.]+) s)")))
      << slow.out;
  EXPECT_LT(std::stod(elapsed[1]), 30.0);  // not the 100 s period
  // SIGINT in the middle of a 100 s wait, once the loop has started.
  sandbox::testing::TempDir dir;
  const std::string log = (dir.path() / "run.txt").string();
  const auto interrupted = sandbox::testing::RunCommand(
      std::string(SANDBOX_BINARY) + " run --rate 0.01 --lcm-url memq:// > " + log +
      " 2>&1 & pid=$!; for i in $(seq 1200); do grep -q '^sandbox run:' " + log +
      " && break; sleep 0.05; done; sleep 0.5; kill -INT $pid; wait $pid; code=$?; cat " + log +
      "; exit $code");
  ASSERT_EQ(interrupted.exit_code, 0) << interrupted.out;
  ASSERT_TRUE(std::regex_search(interrupted.out, elapsed,
                                std::regex(R"(sandbox run: \d+ ticks in ([0-9.]+) s)")))
      << interrupted.out;
  EXPECT_LT(std::stod(elapsed[1]), 30.0);
}

// --web: a bad value is a usage error naming it; an address that cannot be
// bound, an error naming the address; a good one is served and counted.
TEST(RunCommandTest, WebAddressesAreCheckedAndTheViewIsCounted) {
  for (const char* value : {"-1", "70000", "http", "8080x", "127.0.0.1:", ":8080", "''"}) {
    const auto run = RunSandbox("run --duration 0.1 --lcm-url memq:// --web " + std::string(value));
    EXPECT_EQ(run.exit_code, 2) << value << ": " << run.out;
    EXPECT_NE(run.out.find("--web must be PORT or ADDRESS:PORT"), std::string::npos) << run.out;
  }
  const auto bad = RunSandbox("run --duration 0.1 --lcm-url memq:// --web 1.2.3.4.5:0");
  EXPECT_EQ(bad.exit_code, 1) << bad.out;
  EXPECT_NE(bad.out.find("--web: '1.2.3.4.5' is no IP address"), std::string::npos) << bad.out;
  const auto elsewhere = RunSandbox("run --duration 0.1 --lcm-url memq:// --web 192.0.2.1:0");
  EXPECT_EQ(elsewhere.exit_code, 1) << elsewhere.out;
  EXPECT_NE(elsewhere.out.find("--web: cannot listen on 192.0.2.1:0"), std::string::npos)
      << elsewhere.out;
  const auto good = RunSandbox("run --duration 0.3 --lcm-url memq:// --web 0");
  EXPECT_EQ(good.exit_code, 0) << good.out;
  EXPECT_NE(good.out.find("browser view at http://127.0.0.1:"), std::string::npos) << good.out;
  EXPECT_NE(good.out.find("browser view: 0 clients"), std::string::npos) << good.out;
}

TEST(RunCommandTest, BadFrameOptionsFailClearly) {
  sandbox::testing::TempDir dir;
  const auto gif =
      RunSandbox("run --duration 0.1 --lcm-url memq:// --frames gif --out " + dir.path().string());
  EXPECT_NE(gif.exit_code, 0);
  EXPECT_NE(gif.out.find("--frames must be jpg, png, mp4 or avi (or a list like jpg,mp4, or none), "
                         "got 'gif'"),
            std::string::npos)
      << gif.out;
  const auto two = RunSandbox("run --duration 0.1 --lcm-url memq:// --frames jpg,png --out " +
                              dir.path().string());
  EXPECT_NE(two.out.find("--frames: one image and one video format at most"), std::string::npos)
      << two.out;
  const auto scans = RunSandbox("run --duration 0.1 --lcm-url memq:// --scans-every 1");
  EXPECT_NE(scans.out.find("--scans-every needs --out"), std::string::npos) << scans.out;
  // Test aids are hooks (RunHooks), not options of the product.
  const auto stall = RunSandbox("run --duration 0.1 --lcm-url memq:// --stall 50:40");
  EXPECT_EQ(stall.exit_code, 2);
  EXPECT_NE(stall.out.find("--stall"), std::string::npos) << stall.out;
  for (const char* value : {"-3", "1e-9", "1e9", "nan", "''"}) {
    const auto rate =
        RunSandbox("run --duration 0.1 --lcm-url memq:// --rate " + std::string(value));
    EXPECT_EQ(rate.exit_code, 2) << value;
    EXPECT_NE(rate.out.find("--rate"), std::string::npos) << rate.out;
  }
  for (const char* value : {"-1", "0", "inf"}) {
    const auto duration = RunSandbox("run --lcm-url memq:// --duration " + std::string(value));
    EXPECT_EQ(duration.exit_code, 2) << value << ": " << duration.out;
    EXPECT_NE(duration.out.find("--duration"), std::string::npos) << duration.out;
  }
  const auto flag = RunSandbox("run --duration 0.1 --fast");
  EXPECT_EQ(flag.exit_code, 2);
  EXPECT_NE(flag.out.find("--fast"), std::string::npos) << flag.out;
  const auto url = RunSandbox("run --duration 0.1 --lcm-url bogus://nowhere");
  EXPECT_EQ(url.exit_code, 1);
  EXPECT_NE(url.out.find("bogus://nowhere"), std::string::npos) << url.out;
  // The URL is opened before the level loads: a mistyped URL fails at once, whatever the level.
  const auto first = RunSandbox("run /nonexistent/level.toml --lcm-url bogus://nowhere");
  EXPECT_EQ(first.exit_code, 1);
  EXPECT_NE(first.out.find("bogus://nowhere"), std::string::npos) << first.out;
  const auto level = RunSandbox("run /nonexistent/level.toml --duration 0.1");
  EXPECT_EQ(level.exit_code, 1);
  EXPECT_NE(level.out.find("/nonexistent/level.toml"), std::string::npos) << level.out;
  const auto tiff =
      RunSandbox("run --duration 0.1 --lcm-url memq:// --depth tiff --out " + dir.path().string());
  EXPECT_NE(tiff.exit_code, 0);
  EXPECT_NE(tiff.out.find("--depth must be png, npy or exr, got 'tiff'"), std::string::npos)
      << tiff.out;
  const std::string file = (dir.path() / "not_a_folder").string();
  std::ofstream(file) << "x";
  const auto blocked = RunSandbox("run --duration 0.1 --lcm-url memq:// --out " + file);
  EXPECT_EQ(blocked.exit_code, 1);
  EXPECT_NE(blocked.out.find("cannot create the output folder '" + file + "'"), std::string::npos)
      << blocked.out;
}

}  // namespace
