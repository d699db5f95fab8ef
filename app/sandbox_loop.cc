#include "app/sandbox_loop.h"

#include <algorithm>
#include <chrono>
#include <exception>
#include <filesystem>
#include <iomanip>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <string>

#include "app/command_line.h"
#include "app/run_summary.h"
#include "app/thread_priority.h"
#include "web/commands.h"
#include "web/level_model.h"

namespace sandbox::app {
namespace {

using Clock = std::chrono::steady_clock;

// Creates the output folder (and its scans/); returns the statistics file, or "".
std::string PrepareOutDir(const RunOptions& options) {
  if (options.out_dir.empty()) return "";
  const std::filesystem::path dir = options.out_dir;
  CreateOutputFolder(dir.string());
  if (options.scans_every_s > 0.0) CreateOutputFolder((dir / "scans").string());
  return (dir / "ticks.csv").string();
}

}  // namespace

SandboxLoop::SandboxLoop(const RunOptions& options, RunHooks hooks, std::ostream& out,
                         std::ostream& err)
    : options_(options),
      hooks_(std::move(hooks)),
      out_(out),
      err_(err),
      log_(options.replay() ? bridge::OpenEventReader(options.replay_file) : nullptr),
      // A replay feeds its inputs through an in-process link: nothing on the network.
      link_(options.replay() ? "memq://" : options.lcm_url),
      loaded_(LoadCheckedLevel(options.level, {},
                               options.isolate ? Isolation::kAlways : Isolation::kSceneFiles)),
      world_(level_),
      reject_log_(&err),
      cameras_(level_, loaded_.cameras),
      stats_(PrepareOutDir(options)) {
  if (!options_.record_file.empty()) link_.RecordTo(options_.record_file);
  StartFoxglove();
  if (hooks_.published || foxglove_) {
    link_.set_publish_tap([this](const std::string& channel, const void* data, unsigned size) {
      if (hooks_.published) hooks_.published(channel, data, size);
      if (foxglove_feed_) foxglove_feed_->Published(channel, data, size, tick_utime_);
    });
  }
  if (level_.terrain) terrain_ = std::make_unique<scene::TerrainStreamer>(level_);
  // The world's geodetic anchor, for the instruments.
  if (const auto anchor = bridge::WorldAnchor(level_, loaded_.bridges)) geodetic_.emplace(*anchor);
  robots_.resize(level_.robots.size());
  for (std::size_t r = 0; r < level_.robots.size(); ++r) {
    RobotRun& robot = robots_[r];
    const bridge::RobotBridgeConfig& config = loaded_.bridges[r];
    robot.state = std::make_unique<scene::RobotState>(level_.robots[r]);
    robot.feed = std::make_unique<bridge::RobotFeed>(link_, level_, int(r), config,
                                                     options_.lockstep, &reject_log_);
    robot.outputs = std::make_unique<bridge::RobotOutputs>(
        link_, config.channel_prefix,
        config.state_in_pose_convention ? config.pose : bridge::Translation{});
    robot.foxglove_frame = config.channel_prefix;
    const scene::RobotModel& model = level_.robots[r];
    std::set<int> link_nodes;  // its links (a description's), bones and skin joints
    for (const std::string& name : model.links) link_nodes.insert(model.FindNode(name));
    for (const scene::Bone& bone : model.bones) link_nodes.insert(bone.node);
    for (const scene::SkinJoint& joint : model.joints) link_nodes.insert(joint.node);
    for (const int node : link_nodes) {
      if (node < 0) continue;
      const std::string& name = model.nodes[std::size_t(node)].name;
      robot.foxglove_links.emplace_back(
          bridge::FoxgloveLinkFrame(config.channel_prefix,
                                    name.empty() ? "node" + std::to_string(node) : name),
          node);
    }
  }
  std::vector<std::string> prefixes;
  for (const bridge::RobotBridgeConfig& config : loaded_.bridges) {
    prefixes.push_back(config.channel_prefix);
  }
  unknown_robots_ = std::make_unique<bridge::UnknownRobots>(link_, prefixes, &reject_log_);
  if (log_) {
    log_states_ = std::make_unique<bridge::StatesAsInputs>(bridge::RecordedRobots(loaded_.bridges));
  }
  for (const sensors::MountedSensor& mounted : loaded_.sensors) {
    sensors_.emplace_back(mounted);
    sensor_schedules_.emplace_back(mounted.RunsEveryTick() ? 0.0 : mounted.spec.rate_hz);
    RobotRun& robot = robots_[std::size_t(mounted.robot)];
    // Poses kept as far back as the robot's sensors look (and a tick more).
    robot.history =
        sensors::PoseHistory(std::max(robot.history.keep_s(), sensors_.back().history_s()));
    if (robot.face_sensor < 0 && mounted.kind == sensors::SensorKind::kFace) {
      robot.face_sensor = int(sensors_.size() - 1);
    }
  }
  // Cameras: rendered off the loop, into the output folder and/or the live view.
  if (options_.view) {
    if (loaded_.cameras.empty())
      throw CommandError("--view: the level declares no [[robot.camera]]");
    live_view_ = std::make_unique<LiveView>("sandbox: " + level_.name);
  }
  write_frames_ = !options_.out_dir.empty() && !loaded_.cameras.empty() &&
                  (!options_.frames.image_format.empty() || !options_.frames.video_format.empty());
  if (write_frames_ || live_view_) {
    FramePipelineConfig config = options_.frames;
    config.out_dir = write_frames_ ? options_.out_dir : "";
    config.lossless = options_.lockstep;
    if (live_view_) {
      config.show = [this](const std::string& camera, const render::Frame& frame) {
        live_view_->Show(frame, camera);
      };
    }
    if (options_.web_port >= 0 || link_.RecordsViews() || foxglove_) {
      config.written = [this](const std::string& camera, std::int64_t tick, std::int64_t utime,
                              const render::CameraView& view, const render::Frame& frame,
                              const std::filesystem::path& color_file) {
        ShowCameraFrame(camera, tick, view, frame, color_file);
        if (WantsFoxgloveViews()) EmitFoxgloveCamera(camera, utime, view, frame, color_file);
      };
    }
    frames_ = std::make_unique<FramePipeline>(level_, config);
  }
  if (options_.web_port >= 0) {
    web::ServerOptions server;
    server.address = options_.web_address;
    server.port = options_.web_port;
    server.page_dir = SANDBOX_WEB_PAGE_DIR;
    if (options_.web_control) {  // camera commands, applied by the loop as keys
      server.on_text = [this](const std::string& text) -> std::string {
        try {
          const std::string key = web::ParseCameraCommand(text);
          const std::map<std::string, ViewKey> keys = {
              {"next_camera", ViewKey::kNextCamera}, {"pan_left", ViewKey::kPanLeft},
              {"pan_right", ViewKey::kPanRight},     {"tilt_up", ViewKey::kTiltUp},
              {"tilt_down", ViewKey::kTiltDown},     {"zoom_in", ViewKey::kZoomIn},
              {"zoom_out", ViewKey::kZoomOut},       {"overlay", ViewKey::kToggleOverlay}};
          std::lock_guard<std::mutex> lock(web_keys_mutex_);
          web_keys_.push_back(keys.at(key));
          return "";
        } catch (const std::invalid_argument& error) {
          return error.what();
        }
      };
    }
    try {
      web_ = std::make_unique<web::StreamServer>(server);
      web_->SetLevel(web::LevelInfoJson(level_, nullptr, options_.web_control),
                     web::MakeLevelModel(level_).glb);
    } catch (const std::exception& e) {
      throw CommandError(e.what());
    }
  }
  // The scene's meshes copied before the loop starts (its JSON is made where it is written).
  if (foxglove_ || link_.RecordsViews()) {
    foxglove_scene_ = std::make_shared<const std::vector<bridge::SceneMesh>>(FoxgloveScene());
  }
}

SandboxLoop::~SandboxLoop() {
  if (hooks_.before_close) hooks_.before_close(link_);
}

bool SandboxLoop::has_pose() const {
  for (const RobotRun& robot : robots_) {
    if (robot.feed->HasPose()) return true;
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
  std::optional<SignalRoute> signals;  // SIGINT and SIGTERM end the loop, and wake its waits
  if (hooks_.route_signals) signals.emplace(stop_);
  const double period_s = paced ? 1.0 / options_.rate_hz : 0.0;
  Start(period_s, priority);
  // Inputs are drained for at most a quarter of a period (a flood cannot hold the loop).
  const double drain_budget_s = paced ? std::min(0.25 * period_s, 0.005) : 0.001;
  auto at = [this](double s) {
    return start_ + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
  };
  const bool timed = options_.duration_s > 0.0;
  while (!stop_.requested()) {
    const double wall_s = SinceStart();
    if (timed && wall_s >= options_.duration_s) break;
    if (options_.lockstep) {
      bool wait = false;
      if (!NextLockstepInput(wall_s, &wait)) break;
      if (wait) continue;
    }
    if (!TakeViewKeys(drain_budget_s)) {
      if (cameras_.controls().quit) break;
      pacer_.Restart(SinceStart());  // paused
      continue;
    }
    bool overrun = false;
    const double next_s = TickAndRecord(wall_s, drain_budget_s, &overrun);
    if (paced && !overrun) {
      stop_.SleepUntil(at(timed ? std::min(next_s, options_.duration_s) : next_s));
    }
  }
  return Finish();
}

void SandboxLoop::Start(double period_s, const std::string& priority) {
  out_ << "sandbox run: " << level_.name << ", " << level_.robots.size() << " robots, "
       << (options_.sensors ? std::to_string(sensors_.size()) + " sensors, " : "sensors off, ")
       << (options_.publish ? "" : "publishing nothing, ")
       << (options_.replay() ? "replaying " + options_.replay_file
                             : PaceName(options_) + ", LCM " + link_.url())
       << priority << "\n";
  if (web_) out_ << "sandbox run: browser view at " << web_->url() << "\n";
  if (foxglove_) out_ << "sandbox run: Foxglove WebSocket server at " << foxglove_->url() << "\n";
  out_ << std::flush;
  start_ = Clock::now();
  pacer_ = TickPacer(period_s, 0.0);
}

double SandboxLoop::SinceStart() const {
  return std::chrono::duration<double>(Clock::now() - start_).count();
}

double SandboxLoop::TickAndRecord(double wall_s, double drain_budget_s, bool* overrun) {
  const auto tick_start = Clock::now();
  TickRecord record;
  record.tick = tick_;
  record.start_s = std::chrono::duration<double>(tick_start - start_).count();
  record.lateness_ms = 1e3 * pacer_.Lateness(record.start_s);
  Tick(wall_s, drain_budget_s, &record);
  ++tick_;
  if (options_.ticks > 0 && tick_ >= options_.ticks) stop_.Request();
  // 6. Record the tick; the caller waits for the next (or the end of the run, or a stop).
  const auto tick_end = Clock::now();
  record.duration_ms = std::chrono::duration<double, std::milli>(tick_end - tick_start).count();
  const double next_s =
      pacer_.Next(std::chrono::duration<double>(tick_end - start_).count(), overrun);
  stats_.Add(record, *overrun);
  if (web_ && web_->WantsState()) PublishWebState(record, SinceStart());
  if (hooks_.web_state) {
    const bool due = tick_time_s_ >= recorded_samples_due_s_;
    if (due) recorded_samples_due_s_ = tick_time_s_ + hooks_.web_samples_every_s;
    hooks_.web_state(WebState(record, due));
  }
  KeepOriginNearRobot();  // between ticks: the next tick's rays see the new origin
  return next_s;
}

int SandboxLoop::Finish() {
  if (frames_) frames_->Finish();  // queues drained, videos and indexes closed
  scan_files_.Finish();
  link_.FinishRecording();
  return Report(SinceStart()) ? 0 : kExitOutputLost;
}

void SandboxLoop::BeginSteps() {
  if (!options_.lockstep || log_) throw CommandError("stepping needs --lockstep and no --replay");
  Start(0.0, "");
}

bool SandboxLoop::Step(const std::vector<bridge::LogEvent>& events) {
  if (stop_.requested()) return false;
  Arrive(events);
  if (!has_pose()) return false;
  bool overrun = false;
  TickAndRecord(SinceStart(), 0.001, &overrun);
  return true;
}

void SandboxLoop::Arrive(const std::vector<bridge::LogEvent>& events) {
  for (const bridge::LogEvent& event : events) {
    link_.set_input_utime(event.utime);  // a recording stamps the input with its own time
    link_.Inject(event.channel, event.data.data(), unsigned(event.data.size()));
    link_.Drain();
  }
  link_.set_input_utime(-1);
}

void SandboxLoop::Tick(double wall_s, double drain_budget_s, TickRecord* record) {
  const std::int64_t rays_before = caster_.rays_cast() + side_rays_;
  if (hooks_.before_tick) hooks_.before_tick(link_, wall_s);
  std::int64_t now = bridge::NowUtime();
  const double t = ApplyInputs(wall_s, drain_budget_s, &now, record);  // 1-2
  tick_time_s_ = t, tick_utime_ = now;
  if (terrain_) StreamTerrain(t);
  if (options_.sensors) RunDueSensors(t, now);  // 3, and 4: their outputs
  if (options_.publish) PublishStates(now);     // 4
  if (foxglove_feed_ || link_.RecordsViews()) EmitFoxgloveTick(now);
  WriteDueScans(t);
  DirectCameras(t, record);                            // 5
  if (options_.publish) PublishStatusIfDue(t, now);    // 4
  if (options_.publish) PublishSurfacesIfDue(t, now);  // 4
  ReportRecordingFailure();
  if (hooks_.end_of_tick) hooks_.end_of_tick(tick_);
  record->rays = caster_.rays_cast() + side_rays_ - rays_before;
}

bool SandboxLoop::TakeViewKeys(double drain_budget_s) {
  ViewControls& controls = cameras_.controls();
  if (options_.web_control) {  // the browser view's camera commands
    std::vector<ViewKey> keys;
    {
      std::lock_guard<std::mutex> lock(web_keys_mutex_);
      keys.swap(web_keys_);
    }
    for (const ViewKey key : keys) controls.Apply(key, int(loaded_.cameras.size()));
  }
  if (!live_view_) return true;
  for (const ViewKey key : live_view_->TakeKeys()) {
    controls.Apply(key, int(loaded_.cameras.size()));
  }
  if (controls.quit) return false;
  if (controls.paused) {  // the world holds still; inputs keep only their newest
    link_.Drain(drain_budget_s);
    stop_.SleepUntil(Clock::now() + std::chrono::milliseconds(10));
    return false;
  }
  return true;
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
    log_feed_.clear();
    const std::string refused = log_states_->Translate(channel, data, &log_feed_);
    if (!refused.empty()) reject_log_.Note(channel, refused);
    for (bridge::LogEvent& event : log_feed_) event.utime = utime;
    Arrive(log_feed_);
  }
  for (const std::string& prefix : log_states_->TakeNewRobotsFromStates()) {
    err_ << "\rsandbox: " << options_.replay_file << " holds what a run applied (" << prefix
         << "/STATE before any " << prefix << "/POSE): its states are replayed as " << prefix
         << "'s POSE and BONES\n";
  }
  if (!has_pose()) return false;  // the log has ended
  if (wall_s >= next_progress_s_) {
    next_progress_s_ = wall_s + 0.25;
    PrintReplayProgress(*log_, tick_, wall_s, err_);
  }
  return true;
}

double SandboxLoop::ApplyInputs(double wall_s, double drain_budget_s, std::int64_t* now_utime,
                                TickRecord* record) {
  // The newest message per channel (lock-step: the next pose), applied.
  if (!options_.lockstep) link_.Drain(drain_budget_s);
  for (RobotRun& robot : robots_) {
    const bridge::RobotFeed::Changes changes =
        robot.feed->Apply(*now_utime, robot.state.get(), &world_);
    record->inputs += changes.messages;
    if (options_.lockstep && changes.pose) {
      // Lock-step time is input time: the outputs depend on the inputs alone.
      input_clock_.Advance(changes.pose_utime);
      *now_utime = changes.pose_utime;
    }
    for (const std::string& jump : changes.time_jumps) err_ << "sandbox: " << jump << "\n";
  }
  link_.set_record_utime(*now_utime);
  const double t = options_.lockstep ? input_clock_.t_s() : wall_s;
  for (RobotRun& robot : robots_) robot.history.Add(t, robot.state->pose());
  return t;
}

void SandboxLoop::StreamTerrain(double t) {
  robot_positions_.clear();
  for (const RobotRun& robot : robots_)
    robot_positions_.push_back(robot.state->pose().translation());
  terrain_->Update(
      robot_positions_, t, &world_,
      options_.lockstep ? scene::TerrainStreamer::Wait::kAll : scene::TerrainStreamer::Wait::kNone);
  for (const std::string& message : terrain_->TakeMessages())
    err_ << "sandbox: " << message << "\n";
}

void SandboxLoop::RunDueSensors(double t, std::int64_t now_utime) {
  due_.clear();
  for (std::size_t s = 0; s < sensors_.size(); ++s) {
    if (!sensor_schedules_[s].Due(t)) continue;
    sensor_schedules_[s].Done(t);
    due_.push_back(s);
  }
  auto run = [this, t](std::size_t s, sensors::RayCaster& caster) {
    sensors::Sensor& sensor = sensors_[s];
    const sensors::MountedSensor& mounted = sensor.mounted();
    const RobotRun& robot = robots_[std::size_t(mounted.robot)];
    sensors::RayFilter filter;
    filter.ignore_robot = mounted.robot;
    sensor.Run({world_, caster, filter, mounted.Pose(*robot.state), robot.state->pose(),
                &robot.history, t, tick_, robot.feed->input().utime,
                geodetic_ ? &*geodetic_ : nullptr, level_.wind ? &*level_.wind : nullptr});
  };
  if (caster_.threads() > 1 && int(due_.size()) > caster_.threads()) {
    // More sensors than threads: whole sensors over the caster's threads, each casting
    // on its thread alone (one hand-over a tick instead of one a sensor).
    // A sensor's exception is rethrown here, on the loop thread.
    std::exception_ptr failure;
    std::mutex failure_mutex;
    caster_.RunParallel(int(due_.size()), [&](int k) {
      thread_local sensors::RayCaster own_thread(1);
      const std::int64_t before = own_thread.rays_cast();
      try {
        run(due_[std::size_t(k)], own_thread);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(failure_mutex);
        if (!failure) failure = std::current_exception();
      }
      side_rays_ += own_thread.rays_cast() - before;
    });
    if (failure) std::rethrow_exception(failure);
  } else {
    for (const std::size_t s : due_) run(s, caster_);
  }
  for (const std::size_t s : due_) {  // published in the sensors' order
    const sensors::Sensor& sensor = sensors_[s];
    const sensors::MountedSensor& mounted = sensor.mounted();
    RobotRun& robot = robots_[std::size_t(mounted.robot)];
    robot.outputs->Publish(sensor.output(), {mounted.spec.name, mounted.channel}, tick_,
                           robot.feed->input(), now_utime);
  }
}

void SandboxLoop::PublishStates(std::int64_t now_utime) {
  for (RobotRun& robot : robots_) {
    if (robot.face_sensor < 0) {
      robot.outputs->PublishState(*robot.state, robot.feed->input(), now_utime);
      continue;
    }
    // The face frames as the faces were last scanned.
    const sensors::Sensor& face = sensors_[std::size_t(robot.face_sensor)];
    const sensors::FaceFrames X_WF = face.get<sensors::FaceScanner>()->LatestFrames(
        std::get<sensors::FaceScan>(face.output()), face.mounted().Pose(*robot.state));
    robot.outputs->PublishState(*robot.state, robot.feed->input(), now_utime, &X_WF);
  }
}

void SandboxLoop::WriteDueScans(double t) {
  if (options_.scans_every_s <= 0.0 || !scan_file_schedule_.Due(t)) return;
  scan_file_schedule_.Done(t);
  for (const sensors::Sensor& sensor : sensors_) {
    const auto* scan = std::get_if<sensors::FaceScan>(&sensor.output());
    const sensors::FaceScanner* scanner = sensor.get<sensors::FaceScanner>();
    if (scan == nullptr || scan->n == 0 || scanner == nullptr) continue;
    std::ostringstream name;
    name << sensor.mounted().spec.name << "_" << std::setw(6) << std::setfill('0') << tick_;
    scan_files_.Submit(*scan,
                       (std::filesystem::path(options_.out_dir) / "scans" / name.str()).string(),
                       scanner->config().half_extent_m);
  }
}

void SandboxLoop::DirectCameras(double t, TickRecord* record) {
  if (shot_.robots.empty()) {  // what the cameras look at, gathered once
    for (const RobotRun& robot : robots_) {
      shot_.robots.push_back(robot.state.get());
      shot_.feeds.push_back(robot.feed.get());
    }
    shot_.world = &world_;
    shot_.sensors = &sensors_;
  }
  shot_.t_s = t;
  shot_.tick = tick_;
  shot_.utime = tick_utime_;
  if (terrain_) shot_.terrain = terrain_->drawn();
  record->frames += cameras_.Direct(shot_, frames_.get(), write_frames_, live_view_ != nullptr);
}

void SandboxLoop::PublishStatusIfDue(double t, std::int64_t now_utime) {
  // Once a second, and at once when an input turns stale or fresh.
  stale_now_.clear();
  for (const RobotRun& robot : robots_) robot.feed->AppendStale(now_utime, &stale_now_);
  const bool changed = stale_now_ != stale_;
  stale_.swap(stale_now_);
  if (t < next_status_s_ && !changed) return;
  next_status_s_ = t + 1.0;
  const double rate_now = t > 0.0 ? double(tick_) / t : 0.0;
  for (RobotRun& robot : robots_) {
    robot.outputs->PublishStatus(rate_now, tick_, stats_.overruns(),
                                 robot.feed->Channels(now_utime), now_utime);
  }
}

void SandboxLoop::PublishSurfacesIfDue(double t, std::int64_t now_utime) {
  const std::uint64_t revision = world_.surface_revision();
  if (t < next_surfaces_s_ && revision == surfaces_sent_revision_) return;
  next_surfaces_s_ = t + 1.0;
  surfaces_sent_revision_ = revision;
  const std::vector<scene::SurfaceEntry> table = world_.SurfaceTable();
  for (RobotRun& robot : robots_) robot.outputs->PublishSurfaces(table, revision, now_utime);
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

void SandboxLoop::ReportRecordingFailure() {
  if (recording_failure_reported_ || link_.record_error().empty()) return;
  recording_failure_reported_ = true;
  err_ << "sandbox run: recording stopped: " << link_.record_error() << "\n";
}

bool SandboxLoop::Report(double elapsed_s) {
  if (!options_.record_file.empty()) ReportRecordingFailure();
  RunRecord run;
  run.options = &options_;
  run.level_name = level_.name;
  run.ticks = tick_;
  run.elapsed_s = elapsed_s;
  run.stats = &stats_;
  run.replay = log_.get();
  run.origin_moves = origin_moves_;
  run.longest_origin_move_ms = longest_origin_move_ms_;
  run.origin = world_.origin();
  run.scan_files = &scan_files_;
  run.live_view = live_view_.get();
  run.web = web_.get();
  run.foxglove = foxglove_.get();
  run.cameras = &cameras_;
  run.link = &link_;
  run.frames = write_frames_ ? frames_.get() : nullptr;
  for (const RobotRun& robot : robots_) {
    run.feeds.push_back(robot.feed.get());
    run.published.push_back(robot.outputs->published());
  }
  run.unknown_robots = unknown_robots_.get();
  if (terrain_) run.terrain = terrain_->figures();
  return ReportRun(run, out_, err_);
}

}  // namespace sandbox::app
