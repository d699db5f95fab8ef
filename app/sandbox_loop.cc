#include "app/sandbox_loop.h"

#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <iomanip>
#include <sstream>
#include <thread>
#include <variant>

#include "app/command_line.h"
#include "app/stop_signal.h"
#include "app/tick_pacer.h"
#include "sensors/debug_overlay.h"
#include "sensors/range_sensor.h"

namespace sandbox::app {
namespace {

using Clock = std::chrono::steady_clock;

std::string Format(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

// SCHED_FIFO for the calling thread (threads it starts later inherit it; the
// caster's workers and the frame threads, started earlier, do not). False
// when not permitted.
bool RaiseToRealTime() {
  sched_param param{};
  param.sched_priority = 10;  // above every normal thread, below the kernel's own
  return pthread_setschedparam(pthread_self(), SCHED_FIFO, &param) == 0;
}

// Back to normal priority, however the loop ends.
struct NormalPriorityAtExit {
  ~NormalPriorityAtExit() {
    sched_param param{};
    pthread_setschedparam(pthread_self(), SCHED_OTHER, &param);
  }
};

// Creates the output folder (and its scans/); returns the statistics file, or "".
std::string PrepareOutDir(const RunOptions& options) {
  if (options.out_dir.empty()) return "";
  const std::filesystem::path dir = options.out_dir;
  CreateOutputFolder(dir.string());
  if (options.scans_every_s > 0.0) CreateOutputFolder((dir / "scans").string());
  return (dir / "ticks.csv").string();
}

}  // namespace

std::vector<bridge::ChannelStatus> SandboxLoop::RobotRun::Channels(std::int64_t now_utime) const {
  std::vector<bridge::ChannelStatus> channels;
  for (const bridge::LatestInput* in :
       {&inputs->pose(), &inputs->bones(), &inputs->actors(), &inputs->camera()}) {
    // Camera commands come when someone steers: never stale.
    const bool stale = in != &inputs->camera() && in->Stale(now_utime, config.stale_after_s);
    channels.push_back({in->channel(), in->received(), in->superseded(), in->rejected(), stale,
                        in->last_reject_reason()});
  }
  for (const bridge::UdpLatest* socket :
       {net_fdm ? &net_fdm->socket() : nullptr, doubles ? &doubles->socket() : nullptr}) {
    if (socket == nullptr) continue;
    channels.push_back({socket->name(), socket->received(), socket->superseded(),
                        socket->rejected(), false, socket->last_reject_reason()});
  }
  return channels;
}

SandboxLoop::SandboxLoop(const RunOptions& options, RunHooks hooks, std::ostream& out,
                         std::ostream& err)
    : options_(options),
      hooks_(std::move(hooks)),
      out_(out),
      err_(err),
      loaded_(LoadCheckedLevel(options.level, {},
                               options.isolate ? Isolation::kAlways : Isolation::kSceneFiles)),
      world_(level_),
      log_(options.replay() ? std::make_unique<bridge::LogReader>(options.replay_file) : nullptr),
      // A replay feeds its inputs through an in-process link: nothing on the network.
      link_(options.replay() ? "memq://" : options.lcm_url),
      reject_log_(&err),
      stats_(PrepareOutDir(options)) {
  StopSignal::Clear();  // from here on RequestStop() and signals end Run()
  if (!options_.record_file.empty()) link_.RecordTo(options_.record_file);
  robots_.resize(level_.robots.size());
  for (std::size_t r = 0; r < level_.robots.size(); ++r) {
    RobotRun& robot = robots_[r];
    robot.config = loaded_.bridges[r];
    robot.state = std::make_unique<scene::RobotState>(level_.robots[r]);
    robot.inputs = std::make_unique<bridge::RobotInputs>(link_, level_, int(r), robot.config);
    robot.outputs = std::make_unique<bridge::RobotOutputs>(
        link_, robot.config.channel_prefix,
        robot.config.state_in_pose_convention ? robot.config.pose : bridge::Translation{});
    robot.inputs->set_log(&reject_log_);
    robot.inputs->set_lockstep(options_.lockstep);
    if (robot.config.net_fdm_port > 0) {
      robot.net_fdm = std::make_unique<bridge::NetFdmInput>(robot.config);
      robot.net_fdm->set_log(&reject_log_);
    }
    if (robot.config.udp_doubles_port > 0) {
      robot.doubles = std::make_unique<bridge::DoublesInput>(robot.config, level_.robots[r]);
      robot.doubles->set_log(&reject_log_);
    }
  }
  for (const sensors::MountedSensor& m : mounted_) {
    SensorRun run{&m, {}, RateSchedule(m.spec.rate_hz), {}};
    if (const auto* face = std::get_if<sensors::FaceScannerConfig>(&m.config)) {
      run.sensor.emplace<sensors::FaceScanner>(*face);
      run.face_scan = std::get<sensors::FaceScanner>(run.sensor).EmptyScan();
    } else if (const auto* ground = std::get_if<sensors::GroundScannerConfig>(&m.config)) {
      run.sensor.emplace<sensors::GroundScanner>(*ground);
    } else if (const auto* lidar = std::get_if<sensors::LidarConfig>(&m.config)) {
      run.sensor.emplace<sensors::Lidar>(*lidar);
    }
    sensor_runs_.push_back(std::move(run));
  }
  // Each robot's STATE carries its first face scanner's frames.
  for (std::size_t s = 0; s < sensor_runs_.size(); ++s) {
    RobotRun& robot = robots_[std::size_t(sensor_runs_[s].mounted->robot)];
    if (robot.face_run < 0 && std::holds_alternative<sensors::FaceScanner>(sensor_runs_[s].sensor)) {
      robot.face_run = int(s);
    }
  }
  // Each robot keeps its poses over its longest lidar sweep (and a tick more).
  for (const sensors::MountedSensor& m : mounted_) {
    if (const auto* lidar = std::get_if<sensors::LidarConfig>(&m.config)) {
      RobotRun& robot = robots_[std::size_t(m.robot)];
      robot.history = PoseHistory(std::max(robot.history.keep_s(), 2.0 / lidar->rotation_hz));
    }
  }
  for (const sensors::MountedCamera& camera : cameras_) {
    // Cameras without a rate run at 30 Hz.
    camera_runs_.push_back({&camera, sensors::ChaseCamera(camera.chase),
                            RateSchedule(camera.spec.rate_hz > 0.0 ? camera.spec.rate_hz : 30.0)});
  }
  // Cameras: rendered off the loop, into the output folder and/or the live view.
  if (options_.view) {
    if (cameras_.empty()) throw CommandError("--view: the level declares no [[robot.camera]]");
    live_view_ = std::make_unique<LiveView>("sandbox: " + level_.name);
  }
  write_frames_ = !options_.out_dir.empty() && !cameras_.empty() &&
                  (!options_.frames.image_format.empty() || !options_.frames.video_format.empty());
  if (write_frames_ || live_view_) {
    FramePipelineConfig config = options_.frames;
    config.out_dir = write_frames_ ? options_.out_dir : "";
    config.lossless = options_.lockstep;
    if (live_view_) {
      config.show = [this](const std::string& camera, const sensors::Frame& frame) {
        live_view_->Show(frame, camera);
      };
    }
    frames_ = std::make_unique<FramePipeline>(level_, config);
  }
}

SandboxLoop::~SandboxLoop() {
  if (hooks_.before_close) hooks_.before_close(link_);
}

void SandboxLoop::RequestStop() { StopSignal::Request(); }

bool SandboxLoop::has_pose() const {
  for (const RobotRun& robot : robots_) {
    if (robot.inputs->HasPose()) return true;
  }
  return false;
}

int SandboxLoop::Run() {
  // The loop thread at real-time priority when allowed (and when it sleeps
  // between ticks): the kernel then wakes it at once, whatever else runs.
  // Free-running and lock-step loops never sleep between ticks: they would
  // only starve the rest of the machine.
  const bool paced = !options_.lockstep && !options_.free_running();
  std::string priority;
  const NormalPriorityAtExit restore_priority;
  if (options_.realtime && paced) {
    priority = RaiseToRealTime() ? ", real-time priority"
                                 : ", normal priority (real-time needs CAP_SYS_NICE or ulimit -r)";
  }
  const StopSignal signals;  // SIGINT and SIGTERM end the loop, and wake its waits
  const std::string pace = options_.lockstep         ? std::string("lock-step")
                           : options_.free_running() ? std::string("free running")
                                                     : Format(options_.rate_hz) + " Hz";
  out_ << "sandbox run: " << level_.name << ", " << level_.robots.size() << " robots, "
       << mounted_.size() << " sensors, "
       << (options_.replay() ? "replaying " + options_.replay_file : pace + ", LCM " + link_.url())
       << priority << "\n"
       << std::flush;

  const double period_s = paced ? 1.0 / options_.rate_hz : 0.0;
  // Inputs are drained for at most a quarter of a period (a flood cannot hold the loop).
  const double drain_budget_s = paced ? std::min(0.25 * period_s, 0.005) : 0.001;
  const auto start = Clock::now();
  auto seconds_since_start = [&start](Clock::time_point t) {
    return std::chrono::duration<double>(t - start).count();
  };
  auto at = [&start](double s) {
    return start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
  };
  const bool timed = options_.duration_s > 0.0;
  TickPacer pacer(period_s, 0.0);
  while (!StopSignal::requested()) {
    const double wall_s = seconds_since_start(Clock::now());
    if (timed && wall_s >= options_.duration_s) break;
    if (options_.lockstep) {
      bool wait = false;
      if (!NextLockstepInput(wall_s, &wait)) break;
      if (wait) continue;
    }
    const auto tick_start = Clock::now();
    TickRecord record;
    record.tick = tick_;
    record.start_s = seconds_since_start(tick_start);
    record.lateness_ms = 1e3 * pacer.Lateness(record.start_s);
    const std::int64_t rays_before = caster_.rays_cast();
    if (live_view_) {
      for (const ViewKey key : live_view_->TakeKeys()) controls_.Apply(key, int(cameras_.size()));
      if (controls_.quit) break;
      if (controls_.paused) {  // the world holds still; inputs keep only their newest
        link_.Drain(drain_budget_s);
        StopSignal::SleepUntil(Clock::now() + std::chrono::milliseconds(10));
        pacer.Restart(seconds_since_start(Clock::now()));
        continue;
      }
    }
    if (hooks_.before_tick) hooks_.before_tick(link_, wall_s);
    // 1-2. Inputs applied; 3-4. sensors that are due, their outputs, the state.
    std::int64_t now = bridge::NowUtime();
    const double t = ApplyInputs(wall_s, drain_budget_s, &now, &record);
    for (RobotRun& robot : robots_) robot.history.Add(t, robot.state->pose());
    RunDueSensors(t, now);
    PublishStates(now);
    WriteDueScans(t);
    // 5. Cameras that are due: jobs for the render thread (copies, no waiting).
    SubmitDueFrames(t, &record);
    PublishStatusIfDue(t, now);
    ReportRecordingFailure();
    if (const auto stall = options_.stalls_ms.find(tick_); stall != options_.stalls_ms.end()) {
      StopSignal::SleepUntil(Clock::now() +
                             std::chrono::duration_cast<Clock::duration>(
                                 std::chrono::duration<double, std::milli>(stall->second)));
    }
    ++tick_;
    // 6. Record the tick; wait for the next (or the end of the run, or a stop).
    const auto tick_end = Clock::now();
    record.duration_ms = std::chrono::duration<double, std::milli>(tick_end - tick_start).count();
    record.rays = caster_.rays_cast() - rays_before;
    bool overrun = false;
    const double next_s = pacer.Next(seconds_since_start(tick_end), &overrun);
    stats_.Add(record, overrun);
    KeepOriginNearRobot();  // between ticks: the next tick's rays see the new origin
    if (paced && !overrun) {
      StopSignal::SleepUntil(at(timed ? std::min(next_s, options_.duration_s) : next_s));
    }
  }
  if (frames_) frames_->Finish();  // queues drained, videos and indexes closed
  scan_files_.Finish();
  link_.FinishRecording();
  PrintSummary(seconds_since_start(Clock::now()));
  return output_lost_ ? kExitOutputLost : 0;
}

bool SandboxLoop::NextLockstepInput(double wall_s, bool* wait) {
  *wait = false;
  if (!log_) {  // from the network: wait for a pose message
    link_.Drain();
    if (!has_pose()) {
      link_.Wait(100);
      *wait = true;
    }
    return true;
  }
  std::string channel;
  std::vector<std::uint8_t> data;
  std::int64_t utime = 0;
  while (!has_pose() && log_->Next(&channel, &data, &utime)) {
    link_.Inject(channel, data.data(), unsigned(data.size()));
    link_.Drain();
  }
  if (!has_pose()) return false;  // the log has ended
  if (wall_s >= next_progress_s_) {
    next_progress_s_ = wall_s + 0.25;
    const double done = log_->fraction_read();
    err_ << "\rreplay: " << std::setw(3) << int(100 * done) << "% | " << tick_ << " ticks | "
         << std::setprecision(0) << std::fixed << (wall_s > 0 ? double(tick_) / wall_s : 0.0)
         << " ticks/s | " << (done > 0 ? wall_s * (1 - done) / done : 0.0) << " s left  "
         << std::defaultfloat << std::setprecision(6) << std::flush;
  }
  return true;
}

double SandboxLoop::ApplyInputs(double wall_s, double drain_budget_s, std::int64_t* now_utime,
                                TickRecord* record) {
  // The newest message per channel (lock-step: the next pose), applied.
  if (!options_.lockstep) link_.Drain(drain_budget_s);
  for (std::size_t r = 0; r < robots_.size(); ++r) {
    RobotRun& robot = robots_[r];
    const bridge::RobotInputs::Applied applied =
        options_.lockstep ? robot.inputs->ApplyNext(robot.state.get(), &world_)
                          : robot.inputs->Apply(robot.state.get(), &world_);
    record->inputs +=
        int(applied.pose) + int(applied.bones) + int(applied.actors) + int(applied.camera);
    if (options_.lockstep && applied.pose) {
      // Lock-step time is input time: the outputs depend on the inputs alone.
      if (first_input_utime_ < 0) first_input_utime_ = applied.pose_utime;
      *now_utime = applied.pose_utime;
    }
    if (applied.pose) robot.input = {applied.pose_seq, applied.pose_utime};
    bool moved = applied.pose || applied.bones;
    // UDP inputs: the packet's own counter and time where its format has
    // them, else the receive counter and the arrival time.
    auto tag = [now_utime](const bridge::PacketTag& own, std::int64_t received) {
      return bridge::InputTag{own.seq >= 0 ? own.seq : received,
                              own.utime >= 0 ? own.utime : *now_utime};
    };
    if (robot.net_fdm && robot.net_fdm->Apply(robot.state.get())) {
      moved = true;
      ++record->inputs;
      robot.input = tag(robot.net_fdm->last_tag(), robot.net_fdm->socket().received());
    }
    if (robot.doubles && robot.doubles->Apply(robot.state.get())) {
      moved = true;
      ++record->inputs;
      robot.input = tag(robot.doubles->last_tag(), robot.doubles->socket().received());
    }
    if (moved) {
      robot.state->Update();
      world_.UpdateRobot(int(r), *robot.state);
    }
  }
  link_.set_record_utime(*now_utime);
  return options_.lockstep
             ? double(*now_utime - std::max<std::int64_t>(first_input_utime_, 0)) * 1e-6
             : wall_s;
}

void SandboxLoop::RunDueSensors(double t, std::int64_t now_utime) {
  for (SensorRun& run : sensor_runs_) {
    if (!run.schedule.Due(t)) continue;
    run.schedule.Done(t);
    RobotRun& robot = robots_[std::size_t(run.mounted->robot)];
    sensors::RayFilter filter;
    filter.ignore_robot = run.mounted->robot;
    const Eigen::Isometry3d X_WS = run.mounted->Pose(*robot.state);
    const std::string& channel = run.mounted->spec.channel;
    if (const auto* scanner = std::get_if<sensors::FaceScanner>(&run.sensor)) {
      scanner->Scan(world_, caster_, filter, X_WS, tick_, &run.face_scan);
      robot.outputs->PublishFaces(run.face_scan, tick_, robot.input, now_utime, channel);
    } else if (const auto* ground = std::get_if<sensors::GroundScanner>(&run.sensor)) {
      sensors::HeightMap map;
      ground->Scan(world_, caster_, filter, X_WS.translation(), &map);
      robot.outputs->PublishGround(map, robot.input, now_utime, channel);
    } else if (const auto* lidar = std::get_if<sensors::Lidar>(&run.sensor)) {
      // The sweep began 1 / rotation_hz ago: from the mount as it is now, on
      // the robot as it was then, to the mount now.
      const double sweep_s = 1.0 / lidar->config().rotation_hz;
      const Eigen::Isometry3d X_RS = robot.state->pose().inverse() * X_WS;
      sensors::LidarScan scan;
      lidar->Sweep(world_, caster_, filter, robot.history.At(t - sweep_s) * X_RS, X_WS, &scan);
      robot.outputs->PublishLidar(scan, robot.input, now_utime, channel);
    } else if (const auto* ray = std::get_if<sensors::RangeSensorConfig>(&run.mounted->config)) {
      robot.outputs->PublishRange(run.mounted->spec.name,
                                  sensors::MeasureRange(*ray, world_, caster_, filter, X_WS),
                                  robot.input, now_utime, channel);
    }
  }
}

void SandboxLoop::PublishStates(std::int64_t now_utime) {
  for (RobotRun& robot : robots_) {
    if (robot.face_run < 0) {
      robot.outputs->PublishState(*robot.state, robot.input, now_utime);
      continue;
    }
    // The face frames as the faces were last scanned (not scanned yet: the box as it is now).
    const SensorRun* face_run = &sensor_runs_[std::size_t(robot.face_run)];
    const auto& scanner = std::get<sensors::FaceScanner>(face_run->sensor);
    bridge::RobotOutputs::FaceFrames X_WF;
    for (int f = 0; f < 6; ++f) {
      const sensors::ScanFace& face = face_run->face_scan.faces[std::size_t(f)];
      X_WF[std::size_t(f)] =
          face.tick >= 0 ? face.X_WB : scanner.BoxFrame(face_run->mounted->Pose(*robot.state));
    }
    robot.outputs->PublishState(*robot.state, robot.input, now_utime, &X_WF);
  }
}

void SandboxLoop::KeepOriginNearRobot() {
  if (robots_.empty()) return;
  const Eigen::Vector3d p_WR = robots_.front().state->pose().translation();
  if ((p_WR - world_.origin()).norm() <= kOriginShiftDistance_m) return;
  const auto start = Clock::now();
  world_.SetOrigin(p_WR.array().round().matrix());  // whole metres keep whole coordinates exact
  const double ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  ++origin_moves_;
  longest_origin_move_ms_ = std::max(longest_origin_move_ms_, ms);
}

void SandboxLoop::WriteDueScans(double t) {
  if (options_.scans_every_s <= 0.0 || !scan_file_schedule_.Due(t)) return;
  scan_file_schedule_.Done(t);
  for (const SensorRun& run : sensor_runs_) {
    if (run.face_scan.n == 0) continue;
    std::ostringstream name;
    name << run.mounted->spec.name << "_" << std::setw(6) << std::setfill('0') << tick_ << ".ply";
    scan_files_.Submit(run.face_scan,
                       (std::filesystem::path(options_.out_dir) / "scans" / name.str()).string());
  }
}

void SandboxLoop::SubmitDueFrames(double t, TickRecord* record) {
  // The live view's camera: the one the keys chose, or the bridge's.
  for (const RobotRun& robot : robots_) {
    const std::string& name = robot.inputs->active_camera();
    if (name.empty() || name == last_active_camera_) continue;
    last_active_camera_ = name;
    for (std::size_t c = 0; c < cameras_.size(); ++c) {
      if (cameras_[c].spec.name == name) controls_.camera = int(c);
    }
  }
  for (CameraRun& run : camera_runs_) {
    const bool active = live_view_ && &run == &camera_runs_[std::size_t(controls_.camera)];
    const double dt = run.last_s < 0.0 ? 0.0 : t - run.last_s;
    run.last_s = t;
    const RobotRun& robot = robots_[std::size_t(run.camera->robot)];
    sensors::CameraView view = run.camera->view;
    sensors::TrailingCommand steer = robot.inputs->trailing();  // from <ROBOT>/CAMERA
    steer.pan_rad += controls_.steer.pan_rad;                   // and the keys
    steer.tilt_rad += controls_.steer.tilt_rad;
    steer.zoom *= controls_.steer.zoom;
    view.X_WC =
        run.camera->Pose(*robot.state, &run.chase, steer, dt);  // the chase lag advances every tick
    if (run.camera->spec.type == "trailing")
      view.fov_y_rad = sensors::ZoomedFov(view.fov_y_rad, steer.zoom);
    if (!frames_ || (!write_frames_ && !active) || !run.schedule.Due(t)) continue;
    run.schedule.Done(t);
    RenderJob job;
    job.camera = run.camera->spec.name;
    job.tick = tick_;
    job.time_s = t;
    job.view = view;
    job.depth = run.camera->depth;
    job.write = write_frames_;
    job.show = active;
    for (const RobotRun& r : robots_) job.robots.push_back(*r.state);
    for (std::size_t a = 0; a < level_.actors.size(); ++a)
      job.actor_poses.push_back(world_.actor_pose(int(a)));
    job.robot_pose = robot.state->pose();
    if (run.camera->overlay != (active && controls_.overlay)) {  // 'o' flips the view's
      for (const SensorRun& sensor : sensor_runs_) {
        if (sensor.mounted->robot == run.camera->robot) {
          sensors::AddFaceScan(sensor.face_scan, run.camera->overlay_stub_m, &job.overlay);
        }
      }
      sensors::AddBoneFrames(*robot.state, 1.0, &job.overlay);
      sensors::AddActorBounds(level_, job.actor_poses, false, &job.overlay);
    }
    frames_->Submit(std::move(job));
    ++record->frames;
  }
}

void SandboxLoop::PublishStatusIfDue(double t, std::int64_t now_utime) {
  // Which inputs are stale now (camera commands come only when someone steers).
  bool changed = false;
  stale_.resize(3 * robots_.size());
  std::size_t i = 0;
  for (const RobotRun& robot : robots_) {
    for (const bridge::LatestInput* in :
         {&robot.inputs->pose(), &robot.inputs->bones(), &robot.inputs->actors()}) {
      const bool stale = in->Stale(now_utime, robot.config.stale_after_s);
      changed = changed || stale != stale_[i];
      stale_[i++] = stale;
    }
  }
  if (t < next_status_s_ && !changed) return;
  next_status_s_ = t + 1.0;
  const double rate_now = t > 0.0 ? double(tick_) / t : 0.0;
  for (RobotRun& robot : robots_) {
    robot.outputs->PublishStatus(rate_now, tick_, stats_.overruns(), robot.Channels(now_utime),
                                 now_utime);
  }
}

void SandboxLoop::ReportRecordingFailure() {
  if (recording_failure_reported_ || link_.record_error().empty()) return;
  recording_failure_reported_ = true;
  err_ << "sandbox run: recording stopped: " << link_.record_error() << "\n";
}

void SandboxLoop::PrintSummary(double elapsed_s) {
  if (log_) {
    err_ << "\rreplay: " << (log_->stopped_early().empty() ? "100% | " : "") << tick_ << " ticks"
         << std::string(30, ' ') << "\n";
    if (!log_->stopped_early().empty()) {
      err_ << "sandbox run: the log '" << options_.replay_file << "' is " << log_->stopped_early()
           << "; the " << log_->events() << " events before it were replayed\n";
    } else if (tick_ == 0) {
      err_ << "sandbox run: the log '" << options_.replay_file << "' has " << log_->events()
           << " events but no pose message for this level's robots\n";
    }
  }
  const StatsSummary summary = stats_.Summary();
  out_ << "sandbox run: " << tick_ << " ticks in " << std::fixed << std::setprecision(2)
       << elapsed_s << " s (" << (elapsed_s > 0 ? double(tick_) / elapsed_s : 0.0)
       << " Hz), mean tick " << std::setprecision(3) << summary.mean_ms << " ms, "
       << summary.overruns << " overruns\n";
  out_ << "  tick duration: p50 " << summary.p50_ms << " ms, p99 " << summary.p99_ms << " ms, max "
       << summary.max_ms << " ms\n";
  const bool paced = !options_.lockstep && !options_.free_running();
  if (paced) {
    out_ << "  tick lateness: p50 " << summary.lateness_p50_ms << " ms, p99 "
         << summary.lateness_p99_ms << " ms, max " << summary.lateness_max_ms << " ms\n";
  }
  if (origin_moves_ > 0) {
    out_ << "  floating origin: moved " << origin_moves_ << " times, longest "
         << longest_origin_move_ms_ << " ms, now at (" << world_.origin().transpose() << ")\n";
  }
  if (!options_.out_dir.empty()) {
    // Files that cannot be finished (a full disk) are reported; the run's results stand.
    const std::filesystem::path dir = options_.out_dir;
    const std::string mode = options_.free_running() ? std::string("free running")
                             : options_.lockstep     ? std::string("lock-step")
                                                     : Format(options_.rate_hz) + " Hz";
    PlotSeries series{
        stats_.ticks_per_point() == 1
            ? std::string("tick duration")
            : "longest of each " + std::to_string(stats_.ticks_per_point()) + " ticks",
        stats_.PlotPoints()};
    series.frames_per_value = double(stats_.ticks_per_point());
    try {
      PlotFrameDurations({series}, level_.name + ": " + std::to_string(tick_) + " ticks, " + mode,
                         paced ? 1e3 / options_.rate_hz : 0.0, (dir / "ticks.png").string());
    } catch (const std::exception& error) {
      err_ << "sandbox run: warning: " << error.what() << "\n";
      output_lost_ = true;
    }
    if (!stats_.Flush()) {
      err_ << "sandbox run: warning: " << (dir / "ticks.csv").string()
           << " is incomplete (cannot write)\n";
      output_lost_ = true;
    }
    out_ << "  statistics: " << (dir / "ticks.csv").string() << ", " << (dir / "ticks.png").string()
         << "\n";
    if (options_.scans_every_s > 0.0) {
      output_lost_ = output_lost_ || scan_files_.failed() > 0;
      out_ << "  scans: " << scan_files_.written() << " PLY files written, "
           << scan_files_.dropped() << " dropped, " << scan_files_.failed() << " failed"
           << (scan_files_.failed() > 0 ? " (" + scan_files_.error() + ")" : "") << " -> "
           << (dir / "scans").string() << "\n";
    }
  }
  if (live_view_) {
    out_ << "  live view: " << live_view_->shown() << " frames shown, last camera "
         << cameras_[std::size_t(controls_.camera)].spec.name
         << (controls_.overlay ? ", overlay toggled" : "")
         << (controls_.quit ? ", quit by key" : "") << "\n";
  }
  if (!options_.record_file.empty()) {
    ReportRecordingFailure();
    output_lost_ = output_lost_ || !link_.record_error().empty();
    out_ << "  recording: " << link_.recorded() << " messages -> " << options_.record_file
         << (link_.record_error().empty() ? "" : " (INCOMPLETE: " + link_.record_error() + ")")
         << "\n";
  }
  if (frames_ && write_frames_) {
    output_lost_ = output_lost_ || frames_->failed() > 0;
    out_ << "  frames: " << frames_->rendered() << " rendered, " << frames_->written()
         << " written, " << frames_->dropped() << " dropped, " << frames_->failed() << " failed"
         << (frames_->failed() > 0 ? " (" + frames_->error() + ")" : "") << " -> "
         << options_.out_dir << "\n";
  }
  for (const RobotRun& robot : robots_) {
    if (!robot.inputs->active_camera().empty()) {
      out_ << "  " << robot.config.channel_prefix
           << " active camera: " << robot.inputs->active_camera() << "\n";
    }
    for (const bridge::ChannelStatus& channel : robot.Channels(bridge::NowUtime())) {
      out_ << "  " << channel.channel << ": " << channel.received << " received, "
           << channel.superseded << " superseded, " << channel.rejected << " rejected"
           << (channel.rejected > 0 ? " (last: " + channel.last_reject_reason + ")" : "") << "\n";
    }
  }
}

}  // namespace sandbox::app
