// The sensor family: sensors declared in level manifests, their configs and
// mounts, one clear message per mistake, and every kind run through Sensor.

#include "sensors/sensor.h"

#include <gtest/gtest.h>

#include <cmath>

#include "scene/collision_world.h"
#include "sensors/render/mounted_camera.h"
#include "tests/test_util.h"

namespace sandbox::sensors {
namespace {

using Eigen::Vector3d;

std::filesystem::path Robots() {
  return std::filesystem::path(SANDBOX_SOURCE_DIR) / "assets/robots/robots.toml";
}

TEST(SensorTest, BundledLevelsDeclareTheirSensors) {
  const scene::Level level = scene::LoadLevel(Robots());
  const std::vector<MountedSensor> sensors = MakeRobotSensors(level);
  ASSERT_EQ(sensors.size(), 2u);
  EXPECT_EQ(sensors[0].spec.name, "tip_ground");
  EXPECT_EQ(sensors[0].robot, level.FindRobot("ELAHA"));
  const auto& lidar = std::get<LidarConfig>(sensors[1].config);
  EXPECT_EQ(lidar.channels(), 16);
  EXPECT_EQ(lidar.azimuth_steps, 1024);
  EXPECT_NEAR(lidar.elevations_rad.front(), -15.0 * M_PI / 180.0, 1e-12);
  EXPECT_DOUBLE_EQ(sensors[1].spec.rate_hz, 10.0);

  const scene::Level sample = scene::LoadLevel(testing::SampleLevel());
  const std::vector<MountedSensor> on_wing = MakeRobotSensors(sample);
  ASSERT_EQ(on_wing.size(), 2u);
  const auto& face = std::get<FaceScannerConfig>(on_wing[0].config);
  EXPECT_EQ(face.points_per_side(), 51);
  EXPECT_EQ(face.refresh, Refresh::kSixStage);
}

TEST(SensorTest, ASensorOnABoneMovesWithTheBone) {
  const scene::Level level = scene::LoadLevel(Robots());
  const std::vector<MountedSensor> sensors = MakeRobotSensors(level);
  const scene::RobotModel& wing = level.robots[static_cast<std::size_t>(level.FindRobot("ELAHA"))];
  scene::RobotState state(wing);
  const double roll = 4.5 * M_PI / 180.0;
  for (int b = 1; b <= 10; ++b) {
    const double values[2] = {roll, 0.0};
    ASSERT_TRUE(state.SetBone(b, values, 2));
  }
  state.Update();
  // Hand-built chain: spawn (0, 0, 10), joints 0.6 then 1.2 m along -y, each
  // rolled 4.5 degrees; the sensor 1.2 m beyond joint 10.
  Eigen::Isometry3d X = Eigen::Isometry3d(Eigen::Translation3d(0, 0, 10));
  for (int k = 1; k <= 10; ++k) {
    X = X * Eigen::Translation3d(0, k == 1 ? -0.6 : -1.2, 0) *
        Eigen::AngleAxisd(roll, Vector3d::UnitX());
  }
  X = X * Eigen::Translation3d(0, -1.2, 0);
  const Eigen::Isometry3d X_WS = sensors[0].Pose(state);
  EXPECT_LT((X_WS.translation() - X.translation()).norm(), 1e-4) << X_WS.translation().transpose();
  EXPECT_TRUE(X_WS.linear().isApprox(X.linear(), 1e-6));
}

// The sample terrain with the wing carrying one sensor of every kind.
scene::Level EveryKindLevel(testing::TempDir& dir) {
  const std::filesystem::path assets = std::filesystem::path(SANDBOX_SOURCE_DIR) / "assets";
  return scene::LoadLevel(
      dir.Write("level.toml",
                "[[actor]]\nname = \"terrain\"\nfile = \"" +
                    (assets / "sample/generated/terrain.gltf").string() +
                    "\"\n[[robot]]\nname = \"W\"\nfile = \"" +
                    (assets / "robots/generated/flying_wing.gltf").string() +
                    "\"\nbones = [\"root\"]\nposition = [10, -20, 40]\nrpy_deg = [0, 10, 30]\n"
                    "[[robot.sensor]]\nname = \"box\"\ntype = \"face\"\nrefresh = \"full\"\n"
                    "resolution_m = 2\nhalf_extent_m = 40\n"
                    "[[robot.sensor]]\nname = \"below\"\ntype = \"ground\"\nposition = [1, 0, 0]\n"
                    "[[robot.sensor]]\nname = \"spin\"\ntype = \"lidar\"\nchannels = 4\n"
                    "azimuth_steps = 64\nrpy_deg = [0, 20, 0]\n"
                    "[[robot.sensor]]\nname = \"alt\"\ntype = \"ray\"\nrange_m = 200\n"));
}

// Each kind made and run through the family gives its own output, equal to
// what its class's own call computes from the same pose.
TEST(SensorTest, EveryKindRunsThroughTheFamilyAsItsOwnClassWould) {
  testing::TempDir dir;
  const scene::Level level = EveryKindLevel(dir);
  const std::vector<MountedSensor> mounted = MakeRobotSensors(level);
  ASSERT_EQ(mounted.size(), 4u);
  const scene::CollisionWorld world(level);
  RayCaster caster(1);
  scene::RobotState state(level.robots[0]);
  RayFilter filter;
  filter.ignore_robot = 0;
  const SensorKind kinds[] = {SensorKind::kFace, SensorKind::kGround, SensorKind::kLidar,
                              SensorKind::kRange};
  const char* channels[] = {"SCAN_FACE", "GROUND", "LIDAR", "RANGE"};
  int hits = 0;
  for (std::size_t i = 0; i < mounted.size(); ++i) {
    const MountedSensor& m = mounted[i];
    EXPECT_EQ(m.kind, kinds[i]) << m.spec.name;
    EXPECT_EQ(m.channel, channels[i]) << m.spec.name;
    Sensor sensor(m);
    EXPECT_EQ(sensor.output().index(), std::size_t(kinds[i])) << "made empty, of its kind";
    const Eigen::Isometry3d X_WS = m.Pose(state);
    const SensorContext at{world, caster, filter, X_WS, state.pose(), nullptr, 0.0, 0};
    const SensorOutput& output = sensor.Run(at);
    ASSERT_EQ(output.index(), std::size_t(kinds[i])) << m.spec.name;
    if (const auto* scan = std::get_if<FaceScan>(&output)) {
      const FaceScanner own(std::get<FaceScannerConfig>(m.config));
      FaceScan expected = own.EmptyScan();
      own.Scan(world, caster, filter, X_WS, 0, &expected);
      for (std::size_t f = 0; f < 6; ++f) {
        EXPECT_EQ(scan->faces[f].occupancy, expected.faces[f].occupancy) << f;
        for (const std::int8_t o : scan->faces[f].occupancy) hits += o == kOccupied;
      }
    } else if (const auto* map = std::get_if<HeightMap>(&output)) {
      HeightMap expected;
      GroundScanner(std::get<GroundScannerConfig>(m.config))
          .Scan(world, caster, filter, X_WS.translation(), &expected);
      ASSERT_EQ(map->height_m.size(), expected.height_m.size());
      for (std::size_t k = 0; k < expected.height_m.size(); ++k) {
        EXPECT_TRUE(map->height_m[k] == expected.height_m[k] ||
                    (std::isnan(map->height_m[k]) && std::isnan(expected.height_m[k])))
            << k;
        hits += !std::isnan(map->height_m[k]);
      }
    } else if (const auto* sweep = std::get_if<LidarScan>(&output)) {
      LidarScan expected;  // no pose history: the sweep is cast from the pose now
      Lidar(std::get<LidarConfig>(m.config)).Sweep(world, caster, filter, X_WS, X_WS, &expected);
      EXPECT_EQ(sweep->range_m, expected.range_m);
      for (const std::uint8_t h : sweep->hit) hits += h;
    } else if (const auto* reading = std::get_if<RangeReading>(&output)) {
      const RangeReading expected =
          MeasureRange(std::get<RangeSensorConfig>(m.config), world, caster, filter, X_WS);
      EXPECT_EQ(reading->range_m, expected.range_m);
      EXPECT_TRUE(reading->hit);  // straight down from 40 m onto the terrain
      hits += reading->hit;
    }
  }
  EXPECT_GT(hits, 100);  // the outputs saw the terrain
  // What `sandbox info` prints, from each config.
  EXPECT_EQ(mounted[0].Describe(), "face 41x41x6 at 2 m on body");
  EXPECT_EQ(mounted[1].Describe(), "ground +-25 m at 1 m on body");
  EXPECT_EQ(mounted[2].Describe(), "lidar 4x64, 100 m on body");
  EXPECT_EQ(mounted[3].Describe(), "ray 200 m on body");
}

// A lidar run with its robot's pose history starts its sweep from the pose
// the robot had one rotation ago.
TEST(SensorTest, ALidarSweepStartsWhereTheRobotWasOneRotationAgo) {
  testing::TempDir dir;
  const scene::Level level = EveryKindLevel(dir);
  const std::vector<MountedSensor> mounted = MakeRobotSensors(level);
  Sensor lidar(mounted[2]);
  EXPECT_DOUBLE_EQ(lidar.history_s(), 0.2);  // two rotations at 10 Hz
  EXPECT_EQ(Sensor(mounted[0]).history_s(), 0.0);
  const scene::CollisionWorld world(level);
  RayCaster caster(1);
  scene::RobotState state(level.robots[0]);
  PoseHistory history(lidar.history_s());
  const Eigen::Isometry3d X_WR_then(Eigen::Translation3d(0.0, 0.0, 50.0));
  history.Add(0.0, X_WR_then);
  history.Add(0.1, state.pose());
  const SensorContext at{world, caster, {}, mounted[2].Pose(state), state.pose(), &history, 0.1, 1};
  const auto& scan = std::get<LidarScan>(lidar.Run(at));
  // The mount on the robot as it was: the robot's offset from then, then the mount.
  const Eigen::Isometry3d X_WS_start = X_WR_then * state.pose().inverse() * mounted[2].Pose(state);
  EXPECT_TRUE(scan.X_WS_start.isApprox(X_WS_start, 1e-12));
  EXPECT_TRUE(scan.X_WS_end.isApprox(mounted[2].Pose(state), 1e-12));
}

// The error an arm robot with one more [[robot.<kind>]] table (named "s" for
// a sensor, "c" for a camera) gives, from "level.toml" on; "no error" if none.
std::string ErrorOf(const std::string& kind, const std::string& table) {
  testing::TempDir dir;
  const std::string arm = (Robots().parent_path() / "generated/arm.gltf").string();
  const auto file = dir.Write("level.toml", "[[robot]]\nname = \"r\"\nfile = \"" + arm +
                                                "\"\nbones = [\"base\", \"link1\"]\n\n[[robot." +
                                                kind + "]]\nname = \"" +
                                                (kind == "sensor" ? "s" : "c") + "\"\n" + table);
  try {
    const scene::Level level = scene::LoadLevel(file);
    if (kind == "sensor") MakeRobotSensors(level);
    if (kind == "camera") render::MakeRobotCameras(level);
  } catch (const scene::LevelError& error) {
    const std::string message = error.what();
    return message.substr(message.find("level.toml"));
  }
  return "no error";
}

std::string Error(const std::string& sensor_table) { return ErrorOf("sensor", sensor_table); }
std::string CameraError(const std::string& camera_table) { return ErrorOf("camera", camera_table); }

// A setting's own checks name the line of its key (9: the second line of
// the sensor table, after its type); others the table's (6).
TEST(SensorTest, MistakesNameTheSensorAndField) {
  EXPECT_EQ(Error("type = \"face\"\nmount = \"elbow\"\n"),
            "level.toml:6: sensor 's': mount 'elbow' is not a node of arm.gltf (nodes: base, "
            "link1, link2, link3, link4, link5, link6, tool)");
  EXPECT_EQ(Error("type = \"face\"\nresolution_m = 0\n"),
            "level.toml:9: sensor 's': resolution_m must be positive, got 0");
  EXPECT_EQ(Error("type = \"face\"\nresolution_m = -0.5\n"),
            "level.toml:9: sensor 's': resolution_m must be positive, got -0.5");
  EXPECT_EQ(Error("type = \"face\"\nresolution_m = 0.05\n"),
            "level.toml:6: sensor 's': half_extent_m 25 at resolution_m 0.05 makes 6 x 1001 x "
            "1001 = 6012006 samples a scan, over sample_budget 2000000");
  EXPECT_EQ(Error("type = \"face\"\nencoding = \"mm16\"\n"),
            "level.toml:9: sensor 's': 'encoding' must be points, mm or float, got 'mm16'");
  // The budget is the level's to raise.
  EXPECT_EQ(Error("type = \"face\"\nresolution_m = 0.05\nsample_budget = 6100000\n"), "no error");
  EXPECT_EQ(Error("type = \"face\"\nresolutoin_m = 0.5\n"),
            "level.toml:9: sensor 's': unknown key 'resolutoin_m' for a face sensor");
  EXPECT_EQ(Error("type = \"face\"\nrefresh = 6\n"),
            "level.toml:9: sensor 's': 'refresh' must be a string");
  EXPECT_EQ(Error("type = \"sonar\"\n"),
            "level.toml:8: sensor 's': 'type' must be face, ground, lidar, ray, imu, gnss or "
            "air_data, got "
            "'sonar'");
  EXPECT_EQ(Error("type = \"imu\"\naccel_noise_density = -0.1\n"),
            "level.toml:9: sensor 's': accel_noise_density must be zero or positive, got -0.1");
  EXPECT_EQ(Error("type = \"imu\"\ngyro_saturation = nan\n"),
            "level.toml:9: sensor 's': 'gyro_saturation' must be finite, got nan");
  EXPECT_EQ(Error("type = \"imu\"\nseed = -3\n"),
            "level.toml:9: sensor 's': 'seed' must be zero or positive");
  EXPECT_EQ(Error("type = \"imu\"\nrange_m = 3\n"),
            "level.toml:9: sensor 's': unknown key 'range_m' for an imu sensor");
  EXPECT_EQ(Error("type = \"lidar\"\nchannels = 0\n"),
            "level.toml:9: sensor 's': 'channels' must be at least 1");
  // A removed key names what replaced it.
  EXPECT_EQ(Error("type = \"lidar\"\nkernel = \"sweep\"\n"),
            "level.toml:9: sensor 's': 'kernel' is no longer a key: every lidar is cast by the "
            "general caster, faster than the structured sweep kernel on every level measured "
            "(docs/decisions/001-no-structured-lidar-kernel.md); delete the key");
  EXPECT_EQ(Error("type = \"ray\"\nrange_m = nan\n"),
            "level.toml:9: sensor 's': 'range_m' must be finite, got nan");
  EXPECT_EQ(Error("type = \"ray\"\nrate_hz = -1\n"),
            "level.toml:9: sensor 's': 'rate_hz' must be positive");
}

TEST(SensorTest, LensMistakesNameTheCameraAndField) {
  EXPECT_EQ(CameraError("type = \"chase\"\nlens = \"fisheye\"\n"),
            "level.toml:9: camera 'c': a lens is for payload and fixed cameras");
  EXPECT_EQ(CameraError("type = \"fixed\"\nlens = \"kannala\"\n"),
            "level.toml:9: camera 'c': 'lens' must be brown_conrady or fisheye, got 'kannala'");
  EXPECT_EQ(CameraError("type = \"fixed\"\nlens = \"fisheye\"\nk1 = -0.6\n"),
            "level.toml:10: camera 'c': k1 and the other coefficients fold the projection back "
            "inside the image (at 42.7 degrees off the axis)");
  EXPECT_EQ(CameraError("type = \"payload\"\nlens = \"brown_conrady\"\nk4 = 0.1\n"),
            "level.toml:10: camera 'c': 'k4' is for a fisheye lens");
  EXPECT_EQ(CameraError("type = \"payload\"\nlens = \"brown_conrady\"\nfx = -5\n"),
            "level.toml:10: camera 'c': fx and fy must be positive");
  EXPECT_EQ(CameraError("type = \"fixed\"\nlens = \"fisheye\"\nfx = 120\nfy = 120\n"),
            "level.toml:9: camera 'c': the lens sees rays beyond 80 degrees off the axis: "
            "too wide to draw through a pinhole view");
  EXPECT_EQ(CameraError("type = \"fixed\"\nlens = \"fisheye\"\nk1 = 0.02\n"), "no error");
}

TEST(SensorTest, CameraMistakesNameTheCameraAndField) {
  EXPECT_EQ(CameraError("type = \"payload\"\nmount = \"elbow\"\n"),
            "level.toml:6: camera 'c': mount 'elbow' is not a node of arm.gltf (nodes: base, "
            "link1, link2, link3, link4, link5, link6, tool)");
  EXPECT_EQ(CameraError("type = \"chase\"\nwidth = 0\n"),
            "level.toml:6: camera 'c': resolution must be 1 to 8192 pixels a side, got 0 x 480");
  EXPECT_EQ(
      CameraError("type = \"chase\"\nheight = 100000\n"),
      "level.toml:6: camera 'c': resolution must be 1 to 8192 pixels a side, got 640 x 100000");
  EXPECT_EQ(CameraError("type = \"chase\"\nfov_deg = 180\n"),
            "level.toml:6: camera 'c': fov_deg must be at least 0.10 and below 180 degrees, got "
            "180.000000");
  // Numbers that draw blank frames, and sizes beyond the pixel budget.
  EXPECT_EQ(CameraError("type = \"chase\"\nfov_deg = 1e-300\n"),
            "level.toml:6: camera 'c': fov_deg must be at least 0.10 and below 180 degrees, got "
            "0.000000");
  EXPECT_EQ(CameraError("type = \"chase\"\nnear_m = 1e-300\n"),
            "level.toml:6: camera 'c': need 0.0001 m <= near_m < far_m (finite), got near_m "
            "0.000000, far_m 2000.000000");
  EXPECT_EQ(CameraError("type = \"chase\"\nfar_m = inf\n"),
            "level.toml:9: camera 'c': 'far_m' must be finite, got inf");
  EXPECT_EQ(CameraError("type = \"chase\"\nwidth = 8192\nheight = 8192\n"),
            "level.toml:6: camera 'c': 8192 x 8192 = 67108864 pixels, over pixel_budget 8294400");
  EXPECT_EQ(CameraError("type = \"chase\"\nwidth = 8192\nheight = 8192\npixel_budget = 1e9\n"),
            "level.toml:6: camera 'c': pixel_budget must be 1 to 16777216, got 1000000000.000000");
  EXPECT_EQ(CameraError("type = \"chase\"\nwidth = 4096\nheight = 4096\n"
                        "pixel_budget = 16777216\n"),
            "no error");
  EXPECT_EQ(CameraError("type = \"trailing\"\noverlay_stub_m = -1\n"),
            "level.toml:6: camera 'c': overlay_stub_m must be 0 (points) to 100 m");
  EXPECT_EQ(CameraError("type = \"chase\"\nzoom = 2\n"),
            "level.toml:9: camera 'c': unknown key 'zoom' for a chase camera");
  EXPECT_EQ(
      CameraError("type = \"drone\"\n"),
      "level.toml:8: camera 'c': 'type' must be chase, trailing, payload or fixed, got 'drone'");
  EXPECT_EQ(CameraError("type = \"chase\"\nlod_px = -1\n"),
            "level.toml:9: camera 'c': 'lod_px' must be 0 (meshes as given) to 8 pixels, got -1");
  // The look's settings the renderer once clamped, refused with the camera and key named.
  EXPECT_EQ(CameraError("type = \"chase\"\nmsaa = 8\n"),
            "level.toml:9: camera 'c': 'msaa' must be 0 (off), 1 (off) or 4 samples, got 8");
  EXPECT_EQ(CameraError("type = \"chase\"\nanisotropy = 32\n"),
            "level.toml:9: camera 'c': 'anisotropy' must be 1 (off) to 16, got 32");
  EXPECT_EQ(CameraError("type = \"chase\"\nanisotropy = 0\n"),
            "level.toml:9: camera 'c': 'anisotropy' must be 1 (off) to 16, got 0");
  EXPECT_EQ(CameraError("type = \"chase\"\nlod_px = 0.5\n"), "no error");
  EXPECT_EQ(CameraError("type = \"chase\"\ncull_hidden_back_faces = false\n"), "no error");
  EXPECT_EQ(CameraError("type = \"chase\"\ncull_hidden_back_faces = 1\n"),
            "level.toml:9: camera 'c': 'cull_hidden_back_faces' must be true or false");
  EXPECT_EQ(CameraError("type = \"payload\"\nmount = \"link6\"\noverlay = true\n"), "no error");
}

}  // namespace
}  // namespace sandbox::sensors

namespace sandbox::sensors {
namespace {

TEST(SensorTest, SettingsThatMakeNoTraversalAreRefusedAtLoad) {
  EXPECT_EQ(Error("type = \"ray\"\nrange_m = 0\n"),
            "level.toml:9: sensor 's': range_m must be positive, got 0");
  EXPECT_EQ(Error("type = \"lidar\"\nrange_m = 0\n"),
            "level.toml:9: sensor 's': range_m must be positive, got 0");
  EXPECT_EQ(Error("type = \"ground\"\ndepth_m = 0\n"),
            "level.toml:9: sensor 's': depth_m must be positive, got 0");
  EXPECT_EQ(Error("type = \"ray\"\ndirection = [0, 0, 0]\n"),
            "level.toml:9: sensor 's': direction must be a unit vector");
  EXPECT_EQ(Error("type = \"face\"\nposition = [nan, 0, 0]\n"),
            "level.toml:9: sensor 's': 'position' must be finite, got nan");
  EXPECT_EQ(Error("type = \"lidar\"\nrpy_deg = [0, inf, 0]\n"),
            "level.toml:9: sensor 's': 'rpy_deg' must be finite, got inf");
  EXPECT_EQ(Error("type = \"ray\"\nquaternion_wxyz = [0, 0, 0, 0]\n"),
            "level.toml:9: sensor 's': 'quaternion_wxyz' must be a unit quaternion, its norm is 0");
}

}  // namespace
}  // namespace sandbox::sensors
