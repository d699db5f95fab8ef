#include "app/render_command.h"

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <variant>

#include "app/bone_values.h"
#include "app/command_line.h"
#include "app/defaults.h"
#include "app/images.h"
#include "app/loaded_level.h"
#include "scene/collision_world.h"
#include "scene/level.h"
#include "scene/surface_ids.h"
#include "sensors/render/cameras.h"
#include "sensors/render/debug_overlay.h"
#include "sensors/sensor.h"

namespace sandbox::app {
namespace {

const char* kUsage =
    "usage: sandbox render [LEVEL] --camera chase|trailing|payload|fixed --at X,Y,Z[,R,P,Y]\n"
    "                      [--robot NAME] [--robot-at X,Y,Z[,R,P,Y]] [--bones LIST]\n"
    "                      [--bone-values V,V,...] [--width W] [--height H] [--fov DEG]\n"
    "                      [--kind LIST] [--quality Q] [--overlay] [--stub M] [--overlay-colour "
    "C]\n"
    "                      [--isolate]\n"
    "                      --out FILE.jpg|.png\n"
    "  --camera  chase: the spring arm behind the robot; trailing: 25 m behind, 8 m up;\n"
    "            payload: on the robot, looking forward (also writes FILE_depth.png, 16-bit\n"
    "            millimetres); fixed: the camera itself at --at\n"
    "  --at      the robot pose (chase, trailing, payload) or the camera pose (fixed):\n"
    "            metres, roll/pitch/yaw in degrees\n"
    "  --robot-at  the robot pose for a fixed camera (default: its spawn pose)\n"
    "  --bones   bone values as for `sandbox pose`\n"
    "  --bone-values  every bone value at once, flat in bone-map order as <ROBOT>/BONES\n"
    "            carries them (radians, metres, quaternions w x y z)\n"
    "  --kind    the images, a comma list of color, depth (16-bit millimetres), segmentation\n"
    "            (16-bit ids, legend in FILE_seg.csv) and normals (camera frame, 8-bit);\n"
    "            default color (payload: color,depth). Colour goes to FILE, the others to\n"
    "            FILE_depth.png, FILE_seg.png, FILE_normals.png (the first one to FILE\n"
    "            when colour is not asked for)\n"
    "  --quality fast or high (default; shadows, FXAA) or plain (the flat look)\n"
    "  --width, --height, --fov   image size (default 640 x 480) and vertical field of view\n"
    "            in degrees (default 60)\n"
    "  --overlay the debug overlay: the robot's face scanners (or a default one, 1 m over\n"
    "            25 m) scanned in full at the pose, occupied samples red and free green,\n"
    "            bone frames and movable actors' bounds\n"
    "  --stub    draw samples as stubs of M metres along their rays instead of points\n"
    "  --overlay-colour  samples coloured by occupancy (default) or by surface id: surface\n"
    "  --isolate read a manifest's files apart first, so that a crash of assimp is an error\n"
    "            (a scene file as LEVEL always is read so)\n";

// The overlay at one robot state: its face scanners scanned in full.
void BuildOverlay(const scene::Level& level, int robot_index, const scene::RobotState* robot,
                  double stub_m, render::SampleColour colour, render::Overlay* overlay) {
  if (robot != nullptr) {
    scene::CollisionWorld world(level);
    world.UpdateRobot(robot_index, *robot);
    sensors::RayCaster caster;
    sensors::RayFilter filter;
    filter.ignore_robot = robot_index;
    std::vector<std::pair<sensors::FaceScannerConfig, Eigen::Isometry3d>> scanners;
    for (const sensors::MountedSensor& mounted : sensors::MakeRobotSensors(level)) {
      const auto* face = std::get_if<sensors::FaceScannerConfig>(&mounted.config);
      if (face != nullptr && mounted.robot == robot_index) {
        scanners.push_back({*face, mounted.Pose(*robot)});
      }
    }
    if (scanners.empty()) scanners.push_back({sensors::FaceScannerConfig{}, robot->pose()});
    for (auto& [config, X_WS] : scanners) {
      config.refresh = sensors::Refresh::kFull;
      const sensors::FaceScanner scanner(config);
      sensors::FaceScan scan = scanner.EmptyScan();
      scanner.Scan(world, caster, filter, X_WS, 0, &scan);
      render::AddFaceScan(scan, stub_m, overlay, colour);
    }
    render::AddBoneFrames(*robot, 1.0, overlay);
  }
  render::AddActorBounds(level, {}, false, overlay);
}

}  // namespace

int RunRender(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  const auto parsed =
      ParseArgs(args, "render",
                {"--camera", "--at", "--robot", "--robot-at", "--bones", "--bone-values", "--width", "--height", "--fov", "--out",
                 "--stub", "--kind", "--quality", "--overlay-colour"},
                {"--overlay", "--isolate"}, kUsage, err);
  if (!parsed) return 2;
  if (parsed->help) {
    out << kUsage;
    return 0;
  }
  const std::string camera = parsed->Value("--camera", "chase"), out_file = parsed->Value("--out");
  if (parsed->Value("--at").empty() || out_file.empty()) {
    err << "sandbox render: --at and --out are required\n" << kUsage;
    return 2;
  }
  if (camera != "chase" && camera != "trailing" && camera != "payload" && camera != "fixed") {
    err << "sandbox render: --camera must be chase, trailing, payload or fixed, got '" << camera
        << "'\n";
    return 2;
  }
  try {
    const Eigen::Isometry3d X_at = ParsePose(parsed->Value("--at"), "--at");
    render::RenderSettings settings;
    try {
      settings =
          render::RenderSettings::Preset(render::ParseQuality(parsed->Value("--quality", "high")));
      settings.images =
          camera == "payload" ? render::kColorImage | render::kDepthImage : render::kColorImage;
      if (!parsed->Value("--kind").empty()) {
        settings.images = render::ParseImageKinds(parsed->Value("--kind"));
      }
    } catch (const std::invalid_argument& error) {
      throw UsageError(error.what());
    }
    render::CameraView view;
    auto whole = [&](const std::string& option, int fallback) {
      return parsed->values.count(option) ? int(ParseWhole(parsed->Value(option), option, 1, 16384))
                                          : fallback;
    };
    view.width = whole("--width", 640);
    view.height = whole("--height", 480);
    view.fov_y_rad =
        (parsed->values.count("--fov") ? ParseNumber(parsed->Value("--fov"), "--fov") : 60.0) *
        M_PI / 180.0;
    const LoadedLevel loaded = LoadCheckedLevel(
        parsed->level.value_or(kDefaultLevel), {},
        parsed->flags.count("--isolate") > 0 ? Isolation::kAlways : Isolation::kSceneFiles);
    const scene::Level& level = loaded.level;
    std::unique_ptr<scene::RobotState> robot;
    int robot_index = -1;
    if (!level.robots.empty()) {
      const int index =
          parsed->Value("--robot").empty() ? 0 : level.FindRobot(parsed->Value("--robot"));
      if (index < 0) throw UsageError("the level has no robot '" + parsed->Value("--robot") + "'");
      robot_index = index;
      robot = std::make_unique<scene::RobotState>(level.robots[std::size_t(index)]);
      if (camera != "fixed" && !robot->SetPose(X_at)) {
        throw UsageError("--at rejected: " + robot->last_rejection());
      }
      if (!parsed->Value("--robot-at").empty()) {
        if (camera != "fixed") throw UsageError("--robot-at is for a fixed camera (use --at)");
        if (!robot->SetPose(ParsePose(parsed->Value("--robot-at"), "--robot-at")))
          throw UsageError("--robot-at rejected: " + robot->last_rejection());
      }
      if (!parsed->Value("--bone-values").empty()) {
        const std::vector<double> values =
            ParseNumbers(parsed->Value("--bone-values"), "--bone-values");
        if (int(values.size()) != robot->model().num_values) {
          throw UsageError("--bone-values: robot '" + robot->model().name + "' takes " +
                           std::to_string(robot->model().num_values) + " values, got " +
                           std::to_string(values.size()));
        }
        if (!robot->SetBones(values))
          throw UsageError("--bone-values rejected: " + robot->last_rejection());
      }
      if (!parsed->Value("--bones").empty())
        ApplyBones(parsed->Value("--bones"), robot->model(), robot.get());
      robot->Update();
    } else if (camera != "fixed") {
      throw CommandError("a " + camera + " camera needs a robot; the level declares none");
    }
    if (camera == "chase") {
      view.X_WC = render::ChaseCamera({}).Update(robot->pose(), 0.0);
    } else if (camera == "trailing") {
      view.X_WC = render::TrailingPose(robot->pose(), 25.0, 8.0, {});
    } else if (camera == "payload") {
      view.X_WC = robot->pose();
    } else {
      view.X_WC = X_at;
    }
    if (level.terrain) view.far_m = 1.0e6;  // to the horizon
    view.ValidateOrThrow();
    const auto start = std::chrono::steady_clock::now();
    std::unique_ptr<render::Renderer> renderer = render::MakeRenderer();
    renderer->SetLevel(level, OpenCvTextureDecoder(level.limits));
    if (level.terrain) {  // the tiles around the camera, all of them in before the picture
      scene::TerrainStreamer terrain(level);
      terrain.Update({view.X_WC.translation()}, 0.0, nullptr, scene::TerrainStreamer::Wait::kAll);
      for (const std::string& message : terrain.TakeMessages()) {
        err << "sandbox render: " << message << "\n";
      }
      renderer->SetTerrain(terrain.drawn());
    }
    for (const std::string& warning : renderer->warnings())
      err << "sandbox render: warning: " << warning << "\n";
    render::Frame frame;
    std::vector<const scene::RobotState*> robots;
    if (robot) robots.push_back(robot.get());
    render::Overlay overlay;
    if (parsed->flags.count("--overlay")) {
      const double stub_m =
          parsed->values.count("--stub") ? ParseNumber(parsed->Value("--stub"), "--stub") : 0.0;
      const std::string colour = parsed->Value("--overlay-colour", "occupancy");
      if (colour != "occupancy" && colour != "surface") {
        throw UsageError("--overlay-colour must be occupancy or surface, got '" + colour + "'");
      }
      BuildOverlay(
          level, robot_index, robot.get(), stub_m,
          colour == "surface" ? render::SampleColour::kSurface : render::SampleColour::kOccupancy,
          &overlay);
    }
    renderer->Render(view, {}, robots, settings, &frame, &overlay);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    // Said once all is written, so that an error is not run into the line.
    std::ostringstream said;
    said << camera << " camera " << frame.width << " x " << frame.height;
    // Colour to FILE, the other kinds beside it (the first of them to FILE without colour).
    const std::filesystem::path file = out_file;
    bool file_used = false;
    auto path_for = [&](const std::string& suffix) {
      if (!file_used && !(settings.images & render::kColorImage)) {
        file_used = true;
        return file;
      }
      std::filesystem::path beside = file;
      beside.replace_filename(file.stem().string() + suffix + ".png");
      return beside;
    };
    if (settings.images & render::kColorImage) {
      WriteColor(frame, out_file);
      said << ", color -> " << out_file;
    }
    if (settings.images & render::kDepthImage) {
      const std::filesystem::path depth = path_for("_depth");
      WriteDepthMillimetres(frame, depth.string());
      said << ", depth -> " << depth.string();
    }
    if (settings.images & render::kSegmentationImage) {
      const std::filesystem::path ids = path_for("_seg");
      WriteSegmentation(frame, ids.string());
      std::filesystem::path legend = file;
      legend.replace_filename(file.stem().string() + "_seg.csv");
      std::ofstream(legend) << scene::SurfaceIds(level).Csv();
      said << ", segmentation -> " << ids.string() << " (legend " << legend.string() << ")";
    }
    if (settings.images & render::kNormalsImage) {
      const std::filesystem::path normals = path_for("_normals");
      WriteNormals(frame, normals.string());
      said << ", normals -> " << normals.string();
    }
    said << std::fixed << std::setprecision(1) << " (" << ms << " ms with set-up, "
         << renderer->description() << ")\n";
    out << said.str();
    return 0;
  } catch (const UsageError& error) {
    err << "sandbox render: " << error.what() << "\n";
    return 2;
  } catch (const scene::LevelError& error) {
    err << "sandbox render: " << error.what() << "\n";
    return 1;
  } catch (const std::exception& error) {
    err << "sandbox render: " << error.what() << "\n";
    return 1;
  }
}

}  // namespace sandbox::app
