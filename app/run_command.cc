#include "app/run_command.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <pthread.h>
#include <sched.h>

#include <csignal>
#include <filesystem>
#include <map>
#include <iomanip>
#include <memory>
#include <sstream>
#include <thread>
#include <variant>

#include "app/command_line.h"
#include "app/defaults.h"
#include "app/frame_pipeline.h"
#include "app/live_view.h"
#include "app/scan_files.h"
#include "app/tick_stats.h"
#include "bridge/lcm_link.h"
#include "bridge/outputs.h"
#include "bridge/robot_inputs.h"
#include "bridge/udp_inputs.h"
#include "scene/collision_world.h"
#include "scene/level.h"
#include "sensors/debug_overlay.h"
#include "sensors/range_sensor.h"
#include "sensors/robot_sensors.h"

namespace sandbox::app {
namespace {

const char* kUsage =
    "usage: sandbox run [LEVEL] [--rate HZ|max] [--duration S] [--lcm-url URL] [--lockstep]\n"
    "                   [--replay LOG] [--record LOG] [--out DIR] [--frames LIST] [--depth D]\n"
    "                   [--scans-every S] [--view] [--realtime auto|off] [--stall TICK:MS,...]\n"
    "  LEVEL          a level (default: the bundled sample level)\n"
    "  --rate         loop rate in Hz (default 100); max: free running, as fast as it can\n"
    "  --duration     stop after this many seconds (default: run until Ctrl-C)\n"
    "  --lcm-url      LCM URL (default: LCM's own; multicast URLs get a 4 MB receive buffer)\n"
    "  --lockstep     each tick consumes exactly one pose message (waits for it); outputs and\n"
    "                 frames are a function of the inputs alone\n"
    "  --replay       read the inputs from an LCM log file (no network), lock-step, full speed,\n"
    "                 with a progress bar\n"
    "  --record       write every output message to an LCM log file\n"
    "  --out DIR      write into DIR: ticks.csv and ticks.png (frame statistics), the robots'\n"
    "                 camera frames ([[robot.camera]]; render and encoder threads, the loop\n"
    "                 never waits for them) and, with --scans-every, scans\n"
    "  --frames       jpg (default), png, mp4, avi, an image and a video format (jpg,mp4), or\n"
    "                 none (statistics and scans only)\n"
    "  --depth        depth images (payload cameras): png (16-bit mm, default), npy or exr\n"
    "                 (float32 m)\n"
    "  --scans-every  write each face scanner's scan as DIR/scans/<sensor>_<tick>.ply every S s\n"
    "  --view         a window showing the active camera (needs a display); keys: c next camera,\n"
    "                 a/d pan, w/s tilt, +/- zoom (trailing), o overlay, space pause, q quit\n"
    "  --realtime     auto (default): the loop thread at real-time priority (SCHED_FIFO) when\n"
    "                 the user may (root, CAP_SYS_NICE or ulimit -r); off: normal priority\n"
    "  --stall        test aid: sleep MS milliseconds inside tick TICK (the loop's timing)\n"
    "Inputs per robot: <ROBOT>/POSE, /BONES, /ACTORS, /CAMERA (trailing pan, tilt, zoom).\n"
    "Outputs: <ROBOT>/SCAN_FACE, /GROUND, /LIDAR, /RANGE, /STATE, /STATUS (docs/bridge.md).\n";

std::atomic<bool> stop_requested{false};

std::string Format(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}
void OnSignal(int) { stop_requested = true; }

std::int64_t NowUtime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// A robot with its state, inputs, outputs and sensors' latest results.
struct RobotRun {
  bridge::RobotBridgeConfig config;
  std::unique_ptr<scene::RobotState> state;
  std::unique_ptr<bridge::RobotInputs> inputs;
  std::unique_ptr<bridge::NetFdmInput> net_fdm;
  std::unique_ptr<bridge::DoublesInput> doubles;
  std::unique_ptr<bridge::RobotOutputs> outputs;
  bridge::InputTag input;

  // Every input's counters: the LCM channels, then the UDP sockets.
  std::vector<bridge::ChannelStatus> Channels(std::int64_t now_utime) const {
    std::vector<bridge::ChannelStatus> channels;
    for (const bridge::LatestInput* in : {&inputs->pose(), &inputs->bones(), &inputs->actors(),
                                          &inputs->camera()}) {
      // Camera commands come when someone steers: never stale.
      const bool stale = in != &inputs->camera() && in->Stale(now_utime, config.stale_after_s);
      channels.push_back({in->channel(), in->received(), in->superseded(), in->rejected(), stale,
                          in->last_reject_reason()});
    }
    for (const bridge::UdpLatest* socket : {net_fdm ? &net_fdm->socket() : nullptr,
                                            doubles ? &doubles->socket() : nullptr}) {
      if (socket == nullptr) continue;
      channels.push_back({socket->name(), socket->received(), socket->superseded(),
                          socket->rejected(), false, socket->last_reject_reason()});
    }
    return channels;
  }
};

struct SensorRun {
  const sensors::MountedSensor* mounted;
  double next_due_s{0.0};
  sensors::FaceScan face_scan;
};

struct CameraRun {
  const sensors::MountedCamera* camera;
  sensors::ChaseCamera chase;
  double next_due_s{0.0}, last_s{-1.0};
};

// SCHED_FIFO for the calling thread (threads it starts later inherit it; the
// caster's workers, started earlier, do not). False when not permitted.
bool RaiseToRealTime() {
  sched_param param{};
  param.sched_priority = 10;  // above every normal thread, below the kernel's own
  return pthread_setschedparam(pthread_self(), SCHED_FIFO, &param) == 0;
}

// Back to normal priority when the loop ends, however it ends.
struct NormalPriorityAtExit {
  ~NormalPriorityAtExit() {
    sched_param param{};
    pthread_setschedparam(pthread_self(), SCHED_OTHER, &param);
  }
};

// --frames: at most one image and one video format, or none.
void ParseFrames(const std::string& text, FramePipelineConfig* config) {
  config->image_format.clear();
  config->video_format.clear();
  if (text == "none") return;
  std::stringstream list(text);
  std::string format;
  while (std::getline(list, format, ',')) {
    std::string& slot = format == "jpg" || format == "png" ? config->image_format
                        : format == "mp4" || format == "avi" ? config->video_format
                                                             : format;
    if (&slot == &format) {
      throw CommandError("--frames must be jpg, png, mp4 or avi (or a list like jpg,mp4, or none), "
                         "got '" + format + "'");
    }
    if (!slot.empty()) throw CommandError("--frames: one image and one video format at most");
    slot = format;
  }
  if (config->image_format.empty() && config->video_format.empty()) {
    throw CommandError("--frames: nothing to write in '" + text + "' (none writes no frames)");
  }
}

// --stall "TICK:MS,...": milliseconds to sleep inside given ticks.
std::map<std::int64_t, double> ParseStalls(const std::string& text) {
  std::map<std::int64_t, double> stalls;
  std::stringstream list(text);
  std::string item;
  while (std::getline(list, item, ',')) {
    const std::size_t colon = item.find(':');
    std::vector<double> values;
    if (colon != std::string::npos) {
      values = ParseNumbers(item.substr(0, colon) + "," + item.substr(colon + 1), "--stall");
    }
    if (values.size() != 2 || values[0] < 0 || values[1] < 0) {
      throw CommandError("--stall wants TICK:MS items, got '" + item + "'");
    }
    stalls[std::int64_t(values[0])] = values[1];
  }
  return stalls;
}

// Runs the sensors due at time t (input time in lock-step) and publishes their outputs.
void RunDueSensors(double t, std::int64_t tick, std::int64_t now, std::vector<SensorRun>* sensor_runs,
                   std::vector<RobotRun>* robots, const scene::CollisionWorld& world,
                   sensors::RayCaster* caster) {
  for (SensorRun& run : *sensor_runs) {
    if (t < run.next_due_s) continue;
    const double rate = run.mounted->spec.rate_hz;
    run.next_due_s = rate > 0.0 ? std::max(run.next_due_s + 1.0 / rate, t) : t;
    RobotRun& robot = (*robots)[std::size_t(run.mounted->robot)];
    sensors::RayFilter filter;
    filter.ignore_robot = run.mounted->robot;
    const Eigen::Isometry3d X_WS = run.mounted->Pose(*robot.state);
    if (const auto* face = std::get_if<sensors::FaceScannerConfig>(&run.mounted->config)) {
      const sensors::FaceScanner scanner(*face);
      if (run.face_scan.n == 0) run.face_scan = scanner.EmptyScan();
      scanner.Scan(world, *caster, filter, X_WS, tick, &run.face_scan);
      robot.outputs->PublishFaces(run.face_scan, tick, robot.input, now, run.mounted->spec.channel);
    } else if (const auto* ground = std::get_if<sensors::GroundScannerConfig>(&run.mounted->config)) {
      sensors::HeightMap map;
      sensors::GroundScanner(*ground).Scan(world, *caster, filter, X_WS.translation(), &map);
      robot.outputs->PublishGround(map, robot.input, now, run.mounted->spec.channel);
    } else if (const auto* lidar = std::get_if<sensors::LidarConfig>(&run.mounted->config)) {
      sensors::LidarScan scan;
      sensors::Lidar(*lidar).Sweep(world, *caster, filter, X_WS, X_WS, &scan);
      robot.outputs->PublishLidar(scan, robot.input, now, run.mounted->spec.channel);
    } else if (const auto* ray = std::get_if<sensors::RangeSensorConfig>(&run.mounted->config)) {
      robot.outputs->PublishRange(run.mounted->spec.name,
                                  sensors::MeasureRange(*ray, world, *caster, filter, X_WS),
                                  robot.input, now, run.mounted->spec.channel);
    }
  }
}

}  // namespace

int RunLoop(const std::vector<std::string>& args, std::ostream& out, std::ostream& err,
            const RunHooks& hooks) {
  const auto parsed =
      ParseArgs(args, "run",
                {"--rate", "--duration", "--lcm-url", "--replay", "--record", "--out", "--frames",
                 "--depth", "--scans-every", "--stall", "--realtime"},
                {"--lockstep", "--view"}, kUsage, err);
  if (!parsed) return 2;
  if (parsed->help) {
    out << kUsage;
    return 0;
  }
  try {
    const bool free_running = parsed->Value("--rate") == "max";
    const double rate_hz = free_running ? 0.0
                           : parsed->values.count("--rate")
                               ? ParseNumbers(parsed->Value("--rate"), "--rate").at(0)
                               : 100.0;
    const double duration_s = parsed->values.count("--duration")
                                  ? ParseNumbers(parsed->Value("--duration"), "--duration").at(0)
                                  : -1.0;
    if (!free_running && !(rate_hz > 0.0)) throw CommandError("--rate must be positive or max");
    const std::string out_dir = parsed->Value("--out");
    const double scans_every_s =
        parsed->values.count("--scans-every")
            ? ParseNumbers(parsed->Value("--scans-every"), "--scans-every").at(0)
            : 0.0;
    if (parsed->values.count("--scans-every") && (out_dir.empty() || !(scans_every_s > 0.0))) {
      throw CommandError("--scans-every needs --out and a positive number of seconds");
    }
    const std::map<std::int64_t, double> stalls = ParseStalls(parsed->Value("--stall"));
    const std::string realtime = parsed->Value("--realtime", "auto");
    if (realtime != "auto" && realtime != "off") {
      throw CommandError("--realtime must be auto or off, got '" + realtime + "'");
    }
    FramePipelineConfig frame_config;
    ParseFrames(parsed->Value("--frames", "jpg"), &frame_config);
    frame_config.depth_format = parsed->Value("--depth", "png");
    if (frame_config.depth_format != "png" && frame_config.depth_format != "npy" &&
        frame_config.depth_format != "exr") {
      throw CommandError("--depth must be png, npy or exr, got '" + frame_config.depth_format + "'");
    }

    const scene::Level level = scene::LoadLevel(parsed->level.value_or(kDefaultLevel));
    const std::vector<sensors::MountedSensor> mounted = sensors::MakeRobotSensors(level);
    bridge::CheckOutputChannels(level);
    scene::CollisionWorld world(level);
    const std::string replay_file = parsed->Value("--replay");
    const bool replay = !replay_file.empty();
    const bool lockstep = replay || parsed->flags.count("--lockstep") > 0;
    std::unique_ptr<bridge::LogReader> log;
    if (replay) log = std::make_unique<bridge::LogReader>(replay_file);
    // A replay feeds its inputs through an in-process link: nothing on the network.
    bridge::LcmLink link(replay ? "memq://" : parsed->Value("--lcm-url"));
    if (!parsed->Value("--record").empty()) link.RecordTo(parsed->Value("--record"));
    struct CloseHook {
      const RunHooks& hooks;
      bridge::LcmLink& link;
      ~CloseHook() {
        if (hooks.before_close) hooks.before_close(link);
      }
    } close_hook{hooks, link};
    sensors::RayCaster caster;
    if (!out_dir.empty()) {
      std::error_code error;
      std::filesystem::create_directories(out_dir, error);
      if (error || !std::filesystem::is_directory(out_dir)) {
        throw CommandError("cannot create the output folder '" + out_dir + "'");
      }
      if (scans_every_s > 0.0) std::filesystem::create_directories(std::filesystem::path(out_dir) / "scans");
    }
    ScanFileWriter scan_files;
    TickStats stats(out_dir.empty() ? "" : (std::filesystem::path(out_dir) / "ticks.csv").string());

    bridge::RejectLog reject_log(&err);
    std::vector<RobotRun> robots(level.robots.size());
    for (std::size_t r = 0; r < level.robots.size(); ++r) {
      robots[r].config = bridge::RobotBridgeConfig::FromModel(level.robots[r]);
      robots[r].state = std::make_unique<scene::RobotState>(level.robots[r]);
      robots[r].inputs =
          std::make_unique<bridge::RobotInputs>(link, level, int(r), robots[r].config);
      robots[r].outputs = std::make_unique<bridge::RobotOutputs>(
          link, robots[r].config.channel_prefix,
          robots[r].config.state_in_pose_convention ? robots[r].config.pose
                                                    : bridge::Translation{});
      robots[r].inputs->set_log(&reject_log);
      robots[r].inputs->set_lockstep(lockstep);
      if (robots[r].config.net_fdm_port > 0) {
        robots[r].net_fdm = std::make_unique<bridge::NetFdmInput>(robots[r].config);
        robots[r].net_fdm->set_log(&reject_log);
      }
      if (robots[r].config.udp_doubles_port > 0) {
        robots[r].doubles =
            std::make_unique<bridge::DoublesInput>(robots[r].config, level.robots[r]);
        robots[r].doubles->set_log(&reject_log);
      }
    }
    // Cameras: rendered off the loop, into --out and/or the live view.
    const std::vector<sensors::MountedCamera> cameras = sensors::MakeRobotCameras(level);
    std::unique_ptr<LiveView> live_view;
    ViewControls controls;
    if (parsed->flags.count("--view")) {
      if (cameras.empty()) throw CommandError("--view: the level declares no [[robot.camera]]");
      live_view = std::make_unique<LiveView>("sandbox: " + level.name);
    }
    const bool write_frames = !out_dir.empty() && !cameras.empty() &&
                              (!frame_config.image_format.empty() || !frame_config.video_format.empty());
    std::unique_ptr<FramePipeline> frames;
    if (write_frames || live_view) {
      frame_config.out_dir = write_frames ? out_dir : "";
      frame_config.lossless = lockstep;
      if (live_view) {
        frame_config.show = [&live_view](const std::string& camera, const sensors::Frame& frame) {
          live_view->Show(frame, camera);
        };
      }
      frames = std::make_unique<FramePipeline>(level, frame_config);
    }
    std::vector<CameraRun> camera_runs;
    for (const sensors::MountedCamera& camera : cameras) {
      camera_runs.push_back({&camera, sensors::ChaseCamera(camera.chase)});
    }
    std::string last_active_camera;
    std::vector<SensorRun> sensor_runs;
    for (const sensors::MountedSensor& m : mounted) sensor_runs.push_back({&m, 0.0, {}});

    // The loop thread at real-time priority when allowed (and when it sleeps
    // between ticks): the kernel then wakes it at once, whatever else runs.
    std::string priority;
    const NormalPriorityAtExit restore_priority;
    if (realtime == "auto" && !free_running) {
      priority = RaiseToRealTime() ? ", real-time priority"
                                   : ", normal priority (real-time needs CAP_SYS_NICE or ulimit -r)";
    }
    out << "sandbox run: " << level.name << ", " << level.robots.size() << " robots, "
        << mounted.size() << " sensors, "
        << (replay ? "replaying " + replay_file
                   : (lockstep ? std::string("lock-step")
                               : free_running ? std::string("free running") : Format(rate_hz) + " Hz") +
                         ", LCM " + link.url())
        << priority << "\n"
        << std::flush;
    stop_requested = false;
    std::signal(SIGINT, OnSignal);
    std::signal(SIGTERM, OnSignal);

    using Clock = std::chrono::steady_clock;
    const auto period = std::chrono::duration<double>(free_running ? 0.0 : 1.0 / rate_hz);
    const auto start = Clock::now();
    auto deadline = start;
    std::int64_t tick = 0, first_input_utime = -1;
    double next_status_s = 0.0, next_progress_s = 0.0, next_scan_file_s = 0.0;
    auto has_pose = [&] {
      for (const RobotRun& robot : robots) {
        if (robot.inputs->HasPose()) return true;
      }
      return false;
    };
    while (!stop_requested) {
      const double wall_s = std::chrono::duration<double>(Clock::now() - start).count();
      if (duration_s >= 0.0 && wall_s >= duration_s) break;
      // Lock-step: wait for (or, replaying, read up to) the next pose message.
      if (replay) {
        std::string channel;
        std::vector<std::uint8_t> data;
        std::int64_t utime = 0;
        while (!has_pose() && log->Next(&channel, &data, &utime)) {
          link.Inject(channel, data.data(), unsigned(data.size()));
          link.Drain();
        }
        if (!has_pose()) break;  // the log has ended
        if (wall_s >= next_progress_s) {
          next_progress_s = wall_s + 0.25;
          const double done = log->fraction_read();
          err << "\rreplay: " << std::setw(3) << int(100 * done) << "% | " << tick << " ticks | "
              << std::setprecision(0) << std::fixed << (wall_s > 0 ? tick / wall_s : 0.0)
              << " ticks/s | " << (done > 0 ? wall_s * (1 - done) / done : 0.0) << " s left  "
              << std::flush;
        }
      } else if (lockstep) {
        link.Drain();
        if (!has_pose()) {
          link.Wait(100);
          continue;
        }
      }
      const auto tick_start = Clock::now();
      TickRecord record;
      record.tick = tick;
      record.start_s = std::chrono::duration<double>(tick_start - start).count();
      record.lateness_ms =
          lockstep || free_running ? 0.0 : std::chrono::duration<double, std::milli>(tick_start - deadline).count();
      const std::int64_t rays_before = caster.rays_cast();
      std::int64_t now = NowUtime();
      if (live_view) {
        for (const ViewKey key : live_view->TakeKeys()) controls.Apply(key, int(cameras.size()));
        if (controls.quit) break;
        if (controls.paused) {  // the world holds still; inputs keep only their newest
          link.Drain();
          std::this_thread::sleep_for(std::chrono::milliseconds(10));
          deadline = Clock::now();
          continue;
        }
      }
      if (hooks.before_tick) hooks.before_tick(link, wall_s);
      // 1-2. Inputs: the newest message per channel (lock-step: the next pose), applied.
      if (!lockstep) link.Drain();
      for (RobotRun& robot : robots) {
        const bridge::RobotInputs::Applied applied =
            lockstep ? robot.inputs->ApplyNext(robot.state.get(), &world)
                     : robot.inputs->Apply(robot.state.get(), &world);
        record.inputs += int(applied.pose) + int(applied.bones) + int(applied.actors) + int(applied.camera);
        if (lockstep && applied.pose) {
          // Lock-step time is input time: the outputs depend on the inputs alone.
          if (first_input_utime < 0) first_input_utime = applied.pose_utime;
          now = applied.pose_utime;
        }
        if (applied.pose) robot.input = {applied.pose_seq, applied.pose_utime};
        bool moved = applied.pose || applied.bones;
        if (robot.net_fdm && robot.net_fdm->Apply(robot.state.get())) {
          moved = true;
          ++record.inputs;
          robot.input = {robot.net_fdm->socket().received(), now};
        }
        if (robot.doubles && robot.doubles->Apply(robot.state.get())) {
          moved = true;
          ++record.inputs;
          robot.input = {robot.doubles->socket().received(), now};
        }
        if (moved) {
          robot.state->Update();
          world.UpdateRobot(int(&robot - robots.data()), *robot.state);
        }
      }
      const double t =
          lockstep ? double(now - std::max<std::int64_t>(first_input_utime, 0)) * 1e-6 : wall_s;
      link.set_record_utime(now);
      // 3-4. Sensors that are due, and their outputs.
      RunDueSensors(t, tick, now, &sensor_runs, &robots, world, &caster);
      for (RobotRun& robot : robots) {
        robot.outputs->PublishState(*robot.state, robot.input, now);
      }
      if (scans_every_s > 0.0 && t >= next_scan_file_s) {
        next_scan_file_s = std::max(next_scan_file_s + scans_every_s, t);
        for (const SensorRun& run : sensor_runs) {
          if (run.face_scan.n == 0) continue;
          std::ostringstream name;
          name << run.mounted->spec.name << "_" << std::setw(6) << std::setfill('0') << tick << ".ply";
          scan_files.Submit(run.face_scan, (std::filesystem::path(out_dir) / "scans" / name.str()).string());
        }
      }
      // 5. Cameras that are due: a job for the render thread (copies, no waiting).
      // The live view's camera: the one the keys chose, or the bridge's.
      for (const RobotRun& robot : robots) {
        const std::string& name = robot.inputs->active_camera();
        if (name.empty() || name == last_active_camera) continue;
        last_active_camera = name;
        for (std::size_t c = 0; c < cameras.size(); ++c) {
          if (cameras[c].spec.name == name) controls.camera = int(c);
        }
      }
      for (CameraRun& run : camera_runs) {
        const bool active = live_view && &run == &camera_runs[std::size_t(controls.camera)];
        const double dt = run.last_s < 0.0 ? 0.0 : t - run.last_s;
        run.last_s = t;
        const RobotRun& robot = robots[std::size_t(run.camera->robot)];
        sensors::CameraView view = run.camera->view;
        sensors::TrailingCommand steer = robot.inputs->trailing();  // from <ROBOT>/CAMERA
        steer.pan_rad += controls.steer.pan_rad;  // and the keys
        steer.tilt_rad += controls.steer.tilt_rad;
        steer.zoom *= controls.steer.zoom;
        view.X_WC = run.camera->Pose(*robot.state, &run.chase, steer, dt);  // chase lag advances every tick
        if (run.camera->spec.type == "trailing") {
          view.fov_y_rad = sensors::ZoomedFov(view.fov_y_rad, steer.zoom);
        }
        if (!frames || (!write_frames && !active) || t < run.next_due_s) continue;
        const double rate = run.camera->spec.rate_hz > 0.0 ? run.camera->spec.rate_hz : 30.0;
        run.next_due_s = std::max(run.next_due_s + 1.0 / rate, t);
        RenderJob job;
        job.camera = run.camera->spec.name;
        job.tick = tick;
        job.time_s = t;
        job.view = view;
        job.depth = run.camera->depth;
        job.write = write_frames;
        job.show = active;
        for (const RobotRun& r : robots) job.robots.push_back(*r.state);
        for (std::size_t a = 0; a < level.actors.size(); ++a) job.actor_poses.push_back(world.actor_pose(int(a)));
        job.robot_pose = robot.state->pose();
        if (run.camera->overlay != (active && controls.overlay)) {  // 'o' flips the view's
          for (const SensorRun& sensor : sensor_runs) {
            if (sensor.mounted->robot == run.camera->robot) {
              sensors::AddFaceScan(sensor.face_scan, run.camera->overlay_stub_m, &job.overlay);
            }
          }
          sensors::AddBoneFrames(*robot.state, 1.0, &job.overlay);
          sensors::AddActorBounds(level, job.actor_poses, false, &job.overlay);
        }
        frames->Submit(std::move(job));
        ++record.frames;
      }
      if (t >= next_status_s) {
        next_status_s = t + 1.0;
        for (RobotRun& robot : robots) {
          const double rate_now = t > 0.0 ? double(tick) / t : 0.0;
          robot.outputs->PublishStatus(rate_now, tick, stats.overruns(), robot.Channels(now), now);
        }
      }
      if (const auto stall = stalls.find(tick); stall != stalls.end()) {
        std::this_thread::sleep_for(std::chrono::duration<double, std::milli>(stall->second));
      }
      ++tick;
      const auto tick_end = Clock::now();
      record.duration_ms = std::chrono::duration<double, std::milli>(tick_end - tick_start).count();
      record.rays = caster.rays_cast() - rays_before;
      // 6. Wait for the next tick; a late tick starts the next at once, no catching up.
      bool overrun = false;
      if (!lockstep && !free_running) {
        deadline += std::chrono::duration_cast<Clock::duration>(period);
        if (tick_end > deadline) {
          overrun = true;
          deadline = tick_end;
        } else {
          std::this_thread::sleep_until(deadline);
        }
      }
      stats.Add(record, overrun);
    }
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
    if (frames) frames->Finish();  // queues drained, videos and indexes closed
    scan_files.Finish();
    if (replay) {
      err << "\rreplay: " << (log->stopped_early().empty() ? "100% | " : "") << tick << " ticks"
          << std::string(30, ' ') << "\n";
      if (!log->stopped_early().empty()) {
        err << "sandbox run: the log '" << replay_file << "' is " << log->stopped_early()
            << "; the " << log->events() << " events before it were replayed\n";
      } else if (tick == 0) {
        err << "sandbox run: the log '" << replay_file << "' has " << log->events()
            << " events but no pose message for this level's robots\n";
      }
    }
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    const StatsSummary summary = stats.Summary();
    out << "sandbox run: " << tick << " ticks in " << std::fixed << std::setprecision(2) << elapsed
        << " s (" << (elapsed > 0 ? tick / elapsed : 0.0) << " Hz), mean tick "
        << std::setprecision(3) << summary.mean_ms << " ms, " << summary.overruns << " overruns\n";
    out << "  tick duration: p50 " << summary.p50_ms << " ms, p99 " << summary.p99_ms << " ms, max "
        << summary.max_ms << " ms\n";
    if (!lockstep && !free_running) {
      out << "  tick lateness: p50 " << summary.lateness_p50_ms << " ms, p99 "
          << summary.lateness_p99_ms << " ms, max " << summary.lateness_max_ms << " ms\n";
    }
    if (!out_dir.empty()) {
      // Files that cannot be finished (a full disk) are reported; the run's results stand.
      const std::filesystem::path plot = std::filesystem::path(out_dir) / "ticks.png";
      const std::string mode = free_running ? std::string("free running")
                               : lockstep   ? std::string("lock-step")
                                            : Format(rate_hz) + " Hz";
      try {
        PlotSeries series{stats.ticks_per_point() == 1
                              ? std::string("tick duration")
                              : "longest of each " + std::to_string(stats.ticks_per_point()) + " ticks",
                          stats.PlotPoints()};
        series.frames_per_value = double(stats.ticks_per_point());
        PlotFrameDurations({series},
                           level.name + ": " + std::to_string(tick) + " ticks, " + mode,
                           free_running || lockstep ? 0.0 : 1e3 / rate_hz, plot.string());
      } catch (const std::exception& error) {
        err << "sandbox run: warning: " << error.what() << "\n";
      }
      if (!stats.Flush()) {
        err << "sandbox run: warning: " << (std::filesystem::path(out_dir) / "ticks.csv").string()
            << " is incomplete (cannot write)\n";
      }
      out << "  statistics: " << (std::filesystem::path(out_dir) / "ticks.csv").string() << ", "
          << plot.string() << "\n";
      if (scans_every_s > 0.0) {
        out << "  scans: " << scan_files.written() << " PLY files written, " << scan_files.dropped()
            << " dropped, " << scan_files.failed() << " failed"
            << (scan_files.failed() > 0 ? " (" + scan_files.error() + ")" : "") << " -> "
            << (std::filesystem::path(out_dir) / "scans").string() << "\n";
      }
    }
    if (live_view) {
      out << "  live view: " << live_view->shown() << " frames shown, last camera "
          << cameras[std::size_t(controls.camera)].spec.name
          << (controls.overlay ? ", overlay toggled" : "") << (controls.quit ? ", quit by key" : "")
          << "\n";
    }
    if (frames && write_frames) {
      out << "  frames: " << frames->rendered() << " rendered, " << frames->written() << " written, "
          << frames->dropped() << " dropped, " << frames->failed() << " failed"
          << (frames->failed() > 0 ? " (" + frames->error() + ")" : "") << " -> " << out_dir << "\n";
    }
    for (const RobotRun& robot : robots) {
      if (!robot.inputs->active_camera().empty()) {
        out << "  " << robot.config.channel_prefix << " active camera: "
            << robot.inputs->active_camera() << "\n";
      }
      for (const bridge::ChannelStatus& channel : robot.Channels(NowUtime())) {
        out << "  " << channel.channel << ": " << channel.received << " received, "
            << channel.superseded << " superseded, " << channel.rejected << " rejected"
            << (channel.rejected > 0 ? " (last: " + channel.last_reject_reason + ")" : "")
            << "\n";
      }
    }
    return 0;
  } catch (const scene::LevelError& error) {
    err << "sandbox run: " << error.what() << "\n";
    return 1;
  } catch (const std::exception& error) {
    err << "sandbox run: " << error.what() << "\n";
    return 1;
  }
}

}  // namespace sandbox::app
