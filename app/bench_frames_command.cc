#include "app/bench_frames_command.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <numeric>
#include <variant>

#include "app/command_line.h"
#include "app/defaults.h"
#include "app/images.h"
#include "app/tick_stats.h"
#include "bridge/example_flight.h"
#include "bridge/lcm_link.h"
#include "bridge/outputs.h"
#include "scene/collision_world.h"
#include "scene/level.h"
#include "sensors/render/cameras.h"
#include "sensors/render/debug_overlay.h"
#include "sensors/render/mounted_camera.h"
#include "sensors/render/renderer.h"
#include "sensors/sensor.h"

namespace sandbox::app {
namespace {

const char* kUsage =
    "usage: sandbox bench-frames [--frames N] [--runs R] [--quality Q] [--kind LIST] [--out DIR]\n"
    "  {empty level, sample level} x {robot only, + face scanner, + scanner and debug overlay}:\n"
    "  each frame flies the example flight one 10 ms step (pose and bones), scans when asked,\n"
    "  publishes the outputs (memq://) and renders the chase camera 640 x 480 to the end.\n"
    "  --frames  frames per run (default 500)\n"
    "  --runs    runs per case (default 3)\n"
    "  --quality the camera's look: plain, fast (default: the loop cameras' default) or high\n"
    "  --kind    the images rendered, a comma list of color (default), depth, segmentation,\n"
    "            normals\n"
    "  --out     folder for frames.csv and one plot per case (default: bench-frames)\n";

struct Case {
  std::string level;  // empty, sample
  std::string work;   // robot, scanner, overlay
  std::string name() const { return level + "_" + work; }
};

// The pose and bones of the example flight at t, applied as the bridge would.
void Fly(double t, std::int64_t seq, scene::RobotState* robot) {
  sandbox_msgs::robot_pose_t pose;
  sandbox_msgs::bone_values_t bones;
  bridge::ExampleFlight(t, seq, 0, &pose, &bones);
  Eigen::Isometry3d X_WB = Eigen::Isometry3d::Identity();
  X_WB.translation() = Eigen::Vector3d(pose.position[0], pose.position[1], pose.position[2]);
  X_WB.linear() = Eigen::Quaterniond(pose.orientation[0], pose.orientation[1], pose.orientation[2],
                                     pose.orientation[3])
                      .normalized()
                      .toRotationMatrix();
  robot->SetPose(X_WB);
  robot->SetBones(bones.values);
  robot->Update();
}

}  // namespace

int RunBenchFrames(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  const auto parsed =
      ParseArgs(args, "bench-frames", {"--frames", "--runs", "--quality", "--kind", "--out"}, {},
                kUsage, err);
  if (!parsed) return 2;
  if (parsed->help) {
    out << kUsage;
    return 0;
  }
  try {
    auto whole = [&](const std::string& option, int fallback) {
      return parsed->values.count(option)
                 ? int(ParseWhole(parsed->Value(option), option, 1, 1000000))
                 : fallback;
    };
    const int frames = whole("--frames", 500), runs = whole("--runs", 3);
    const std::filesystem::path dir = parsed->Value("--out", "bench-frames");
    render::RenderSettings look;
    try {
      look =
          render::RenderSettings::Preset(render::ParseQuality(parsed->Value("--quality", "fast")));
      look.images = render::ParseImageKinds(parsed->Value("--kind", "color"));
    } catch (const std::invalid_argument& error) {
      throw UsageError(error.what());
    }
    CreateOutputFolder(dir.string());
    std::ofstream csv(dir / "frames.csv");
    csv << "case,run,frame,duration_ms\n" << std::fixed << std::setprecision(4);

    const scene::Level sample = scene::LoadLevel(kDefaultLevel);
    scene::Level empty = sample;  // the robot alone
    empty.actors.clear();
    const std::vector<sensors::MountedSensor> mounted = sensors::MakeRobotSensors(sample);
    const sensors::FaceScannerConfig* scanner_config = nullptr;
    const sensors::MountedSensor* scanner_mount = nullptr;
    for (const sensors::MountedSensor& m : mounted) {
      if (const auto* face = std::get_if<sensors::FaceScannerConfig>(&m.config)) {
        scanner_config = face;
        scanner_mount = &m;
      }
    }
    if (scanner_config == nullptr) throw CommandError("the sample level has no face scanner");
    const sensors::FaceScanner scanner(*scanner_config);
    const std::vector<render::MountedCamera> cameras = render::MakeRobotCameras(sample);
    render::MountedCamera chase_camera;
    for (const render::MountedCamera& c : cameras) {
      if (c.kind == render::CameraKind::kChase) chase_camera = c;
    }
    std::unique_ptr<render::Renderer> renderer = render::MakeRenderer();
    sensors::RayCaster caster;
    bridge::LcmLink link("memq://");
    bridge::RobotOutputs outputs(link, "ELAHA", {});

    out << "sandbox bench-frames: " << runs << " runs of " << frames << " frames a case, chase "
        << chase_camera.view.width << " x " << chase_camera.view.height << ", "
        << parsed->Value("--quality", "fast") << " look, " << render::ImageKindsText(look.images)
        << ", " << renderer->description() << "\n\n"
        << std::left << std::setw(18) << "case" << std::right << std::setw(10) << "mean ms"
        << std::setw(10) << "p50 ms" << std::setw(10) << "p99 ms" << std::setw(10) << "max ms"
        << std::setw(10) << "fps" << std::setw(10) << "vs robot"
        << "  runs' means (ms)\n";
    double robot_only_mean = 0.0;  // the level's first case: the reference
    const int colors[3][3] = {{200, 80, 30}, {40, 160, 40}, {30, 60, 220}};
    for (const std::string level_name : {"empty", "sample"}) {
      const scene::Level& level = level_name == "empty" ? empty : sample;
      renderer = render::MakeRenderer();  // a fresh context per level
      renderer->SetLevel(level, OpenCvTextureDecoder(level.limits));
      scene::CollisionWorld world(level);
      for (const std::string work : {"robot", "scanner", "overlay"}) {
        const Case c{level_name, work};
        std::vector<PlotSeries> series;
        std::vector<double> all, run_means;
        for (int run = 0; run < runs; ++run) {
          scene::RobotState robot(level.robots[0]);
          render::ChaseCamera chase(chase_camera.chase);
          sensors::SensorOutput output = scanner.EmptyScan();  // as the loop publishes it
          sensors::FaceScan& scan = std::get<sensors::FaceScan>(output);
          sensors::RayFilter filter;
          filter.ignore_robot = 0;
          render::Frame frame;
          std::vector<double> durations;
          const int warm_up = 20;  // shaders, caches and buffers settle first; not counted
          for (int i = -warm_up; i < frames; ++i) {
            const auto start = std::chrono::steady_clock::now();
            const double t = 0.01 * (i + warm_up);
            Fly(t, i + warm_up, &robot);
            world.UpdateRobot(0, robot);
            if (work != "robot") {
              scanner.Scan(world, caster, filter, scanner_mount->Pose(robot), i + warm_up, &scan);
              outputs.Publish(output, {"scanner", "SCAN_FACE"}, i + warm_up, {i + warm_up, 0}, 0);
            }
            outputs.PublishState(robot, {i + warm_up, 0}, 0);
            render::CameraView view = chase_camera.view;
            view.X_WC = chase.Update(robot.pose(), 0.01);
            render::Overlay overlay;
            if (work == "overlay") {
              render::AddFaceScan(scan, 0.0, &overlay);
              render::AddBoneFrames(robot, 1.0, &overlay);
              render::AddActorBounds(level, {}, false, &overlay);
            }
            renderer->Render(view, {}, {&robot}, look, &frame, &overlay);
            link.Drain();
            if (i < 0) continue;
            durations.push_back(
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                    .count());
            csv << c.name() << ',' << run << ',' << i << ',' << durations.back() << '\n';
          }
          run_means.push_back(std::accumulate(durations.begin(), durations.end(), 0.0) /
                              double(frames));
          all.insert(all.end(), durations.begin(), durations.end());
          series.push_back({"run " + std::to_string(run + 1), durations, colors[run % 3][0],
                            colors[run % 3][1], colors[run % 3][2]});
        }
        const double mean = std::accumulate(all.begin(), all.end(), 0.0) / double(all.size());
        if (work == "robot") robot_only_mean = mean;
        std::ostringstream means;
        means << std::fixed << std::setprecision(2);
        for (std::size_t r = 0; r < run_means.size(); ++r) means << (r ? "/" : "") << run_means[r];
        out << std::left << std::setw(18) << c.name() << std::right << std::fixed
            << std::setprecision(2) << std::setw(10) << mean << std::setw(10) << Quantile(all, 0.5)
            << std::setw(10) << Quantile(all, 0.99) << std::setw(10)
            << *std::max_element(all.begin(), all.end()) << std::setw(10) << std::setprecision(0)
            << 1e3 / mean << std::setw(9) << std::setprecision(2) << mean / robot_only_mean << "x  "
            << means.str() << "\n"
            << std::flush;
        PlotFrameDurations(
            series,
            "bench-frames " + c.name() + ": frame duration, " + std::to_string(runs) + " runs", 0.0,
            (dir / (c.name() + ".png")).string());
      }
    }
    out << "\nframes.csv and one plot per case -> " << dir.string() << "\n";
    return 0;
  } catch (const UsageError& error) {
    err << "sandbox bench-frames: " << error.what() << "\n";
    return 2;
  } catch (const std::exception& error) {
    err << "sandbox bench-frames: " << error.what() << "\n";
    return 1;
  }
}

}  // namespace sandbox::app
