#pragma once
// The loop of `sandbox run`: a conductor that calls each part once per tick,
// in the order of ../shared/DESIGN.md, "One tick of the loop"
// (docs/explanation/architecture.md shows where each step lives):
//   1-2. the inputs drained and applied (bridge::RobotFeed, one per robot);
//   3.   the sensors that are due run (sensors::Sensor; several at once over
//        the caster's threads, each on a one-thread caster);
//   4.   their outputs, each robot's state and the status heartbeat published
//        (bridge::RobotOutputs);
//   5.   the cameras that are due handed to the render thread (CameraDirector,
//        FramePipeline);
//   6.   the tick recorded (TickStats); then the wait for the next.
// A late tick is followed at once by the next; ticks are never bunched to
// catch up. The end of the run is reported by ReportRun (run_summary.h).
// sandbox_loop_web.cc holds the loop's part in the browser view.
//
// Threads: everything here runs on the loop thread (the caller of Run, or of
// BeginSteps, Step and Finish). It starts the render and encoder threads
// (FramePipeline) and the scan-file writer, and takes real-time priority for
// itself when asked and allowed. The live view's window is run by the caller
// on the main thread.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <ostream>
#include <vector>

#include "app/camera_director.h"
#include "app/foxglove_feed.h"
#include "app/frame_pipeline.h"
#include "app/input_clock.h"
#include "app/live_view.h"
#include "app/loaded_level.h"
#include "app/rate_schedule.h"
#include "app/run_hooks.h"
#include "app/run_options.h"
#include "app/scan_files.h"
#include "app/stop_request.h"
#include "app/tick_pacer.h"
#include "app/tick_stats.h"
#include "bridge/foxglove_messages.h"
#include "bridge/lcm_link.h"
#include "bridge/outputs.h"
#include "bridge/recorded_states.h"
#include "bridge/reject_log.h"
#include "bridge/robot_feed.h"
#include "bridge/unknown_robots.h"
#include "scene/collision_world.h"
#include "scene/geodetic.h"
#include "scene/level.h"
#include "scene/robot_state.h"
#include "scene/terrain_streamer.h"
#include "sensors/pose_history.h"
#include "sensors/ray_caster.h"
#include "sensors/sensor.h"
#include "web/foxglove_server.h"
#include "web/stream_server.h"

namespace sandbox::app {

class SandboxLoop {
 public:
  // Loads the level and opens what the options ask for (LCM, the log, the
  // output folder, the frame threads, the window). Throws scene::LevelError
  // for the level, std::runtime_error (CommandError) for the rest.
  SandboxLoop(const RunOptions& options, RunHooks hooks, std::ostream& out, std::ostream& err);
  ~SandboxLoop();
  SandboxLoop(const SandboxLoop&) = delete;
  SandboxLoop& operator=(const SandboxLoop&) = delete;

  // The exit code of a run that finished but could not write all of its
  // output (frames, scans, the recording or the statistics).
  static constexpr int kExitOutputLost = 3;
  // The floating origin (scene::CollisionWorld::SetOrigin) follows the first
  // robot: when it is farther than this from the origin, the origin moves to
  // its position rounded to whole metres, after the tick.
  static constexpr double kOriginShiftDistance_m = 1000.0;

  // Runs until the duration ends, a replayed log ends, SIGINT/SIGTERM, the
  // live view's q or RequestStop(); then finishes the files and prints the
  // summary to `out`. Returns 0, or kExitOutputLost.
  int Run();
  // Stepped instead of Run() (lock-step options without --replay; the
  // caller's thread is the loop thread): BeginSteps() once; Step() a tick,
  // with the messages that arrive for it (false: no tick ran, because no
  // robot has a pose waiting or the run has ended, see ended()); then
  // Finish() once, which returns as Run() does.
  void BeginSteps();
  bool Step(const std::vector<bridge::LogEvent>& events);
  bool ended() const { return stop_.requested(); }
  int Finish();
  // Any thread: ends Run() after the current tick (or at once from a wait).
  void RequestStop() { stop_.Request(); }
  // The live view when asked for (its window is the caller's to run), or null.
  LiveView* live_view() { return live_view_.get(); }
  const scene::Level& level() const { return level_; }
  // The level with its sensors, cameras and robots' channels.
  const LoadedLevel& loaded_level() const { return loaded_; }
  // The browser view's address (--web), or "".
  std::string web_url() const { return web_ ? web_->url() : std::string(); }
  std::string foxglove_url() const { return foxglove_ ? foxglove_->url() : std::string(); }

 private:
  // A robot: its state, what drives it and what it publishes.
  struct RobotRun {
    std::unique_ptr<scene::RobotState> state;
    std::unique_ptr<bridge::RobotFeed> feed;
    std::unique_ptr<bridge::RobotOutputs> outputs;
    sensors::PoseHistory history;  // its poses, as far back as its sensors need
    int face_sensor{-1};           // its first face scanner in sensors_ (STATE's face frames)
    std::string foxglove_frame;    // its frame in Foxglove: the channel prefix
    std::vector<std::pair<std::string, int>> foxglove_links;  // frame id, node
  };
  // Lock-step: makes the next pose available (reading the replayed log up to
  // it). False: stop (the log has ended); *wait: nothing yet, try again.
  bool NextLockstepInput(double wall_s, bool* wait);
  // Lock-step inputs (a replay's, or a step's) handed to the robots as if
  // they had arrived, one at a time.
  void Arrive(const std::vector<bridge::LogEvent>& events);
  // The banner printed, the clock and the pacer started.
  void Start(double period_s, const std::string& priority);
  double SinceStart() const;  // seconds since Start()
  // A tick (Tick) recorded (6, and what follows a tick); returns when the
  // next tick is due and sets *overrun when this one ran past it.
  double TickAndRecord(double wall_s, double drain_budget_s, bool* overrun);
  // The live view's keys; false when the tick is skipped (paused or quit).
  bool TakeViewKeys(double drain_budget_s);
  // Steps 1-5 of a tick, each below in order; the caller records it (6).
  void Tick(double wall_s, double drain_budget_s, TickRecord* record);
  double ApplyInputs(double wall_s, double drain_budget_s, std::int64_t* now_utime,
                     TickRecord* record);
  // Terrain tiles near the robots in, far ones out (lock-step: waits for them).
  void StreamTerrain(double t);
  void RunDueSensors(double t, std::int64_t now_utime);
  void PublishStates(std::int64_t now_utime);
  void WriteDueScans(double t);
  void DirectCameras(double t, TickRecord* record);
  void PublishStatusIfDue(double t, std::int64_t now_utime);
  // The surface table on each robot's WORLD channel: at the first tick, when
  // terrain tiles come or go, and once a second.
  void PublishSurfacesIfDue(double t, std::int64_t now_utime);
  // Between ticks: the browser view's state (--web), handed to its server.
  void PublishWebState(const TickRecord& record, double wall_s);
  // On the frame pipeline's encoder thread: a written frame to the browser
  // view (its JPEG, or one encoded), kWebCameraHz a camera while a client is there.
  void ShowCameraFrame(const std::string& camera, std::int64_t tick, const render::CameraView& view,
                       const render::Frame& frame, const std::filesystem::path& color_file);
  // The browser view's state after a tick, with the sensors' samples or without.
  web::StreamState WebState(const TickRecord& record, bool with_samples);
  // Between ticks: the floating origin to the first robot when it is far from it.
  void KeepOriginNearRobot();
  // Says once that the recording (--record) could not be written.
  void ReportRecordingFailure();
  bool Report(double elapsed_s);
  bool has_pose() const;

  const RunOptions options_;
  const RunHooks hooks_;
  std::ostream& out_;
  std::ostream& err_;
  StopRequest stop_;
  // The replayed log and the link before the level: a bad file or URL fails at once.
  std::unique_ptr<bridge::EventReader> log_;
  std::unique_ptr<bridge::StatesAsInputs> log_states_;  // a --record log's STATEs as inputs
  std::vector<bridge::LogEvent> log_feed_;
  bridge::LcmLink link_;
  const LoadedLevel loaded_;
  const scene::Level& level_{loaded_.level};
  scene::CollisionWorld world_;
  std::unique_ptr<scene::TerrainStreamer> terrain_;   // when the level has [[terrain]]
  std::optional<scene::LocalTangentPlane> geodetic_;  // its anchor, for the instruments
  std::vector<Eigen::Vector3d> robot_positions_;
  sensors::RayCaster caster_;
  bridge::RejectLog reject_log_;
  std::vector<RobotRun> robots_;
  std::unique_ptr<bridge::UnknownRobots> unknown_robots_;  // poses for robots not here
  std::vector<sensors::Sensor> sensors_;
  std::vector<RateSchedule> sensor_schedules_;  // one per sensor
  std::vector<std::size_t> due_;                // the sensors due this tick
  std::atomic<std::int64_t> side_rays_{0};      // cast by the sensors' own-thread casters
  CameraDirector cameras_;
  ScanFileWriter scan_files_;
  TickStats stats_;
  std::unique_ptr<LiveView> live_view_;  // before frames_: frames_ calls into it
  bool write_frames_{false};
  std::unique_ptr<FramePipeline> frames_;
  std::unique_ptr<web::StreamServer> web_;  // the browser view (--web)
  // The live Foxglove server (--foxglove) and what feeds it, and the
  // Foxglove views no LCM message carries, to it and to an MCAP recording
  // (sandbox_loop_foxglove.cc). The server goes first (its thread may still
  // run the feed's work).
  void StartFoxglove();
  bool WantsFoxgloveViews() const;  // a recording takes them or a client is there
  // Any thread: a view to the recording and the live server, made by `make`
  // on their threads from about `bytes` of data it holds.
  void EmitFoxgloveView(const std::string& topic, bridge::MakeView make, std::int64_t utime,
                        std::size_t bytes);
  // After a tick's STATEs: the scene (first tick; latched for later
  // clients), and while wanted each robot's link frames and the movable
  // actors' frames.
  void EmitFoxgloveTick(std::int64_t utime);
  std::vector<bridge::SceneMesh> FoxgloveScene() const;
  // On the frame pipeline's encoder thread: a written frame as an image, its
  // calibration and its optical frame.
  void EmitFoxgloveCamera(const std::string& camera, std::int64_t utime,
                          const render::CameraView& view, const render::Frame& frame,
                          const std::filesystem::path& color_file);
  std::shared_ptr<const std::vector<bridge::SceneMesh>> foxglove_scene_;  // made at the start
  bool foxglove_scene_sent_{false};
  std::unique_ptr<FoxgloveFeed> foxglove_feed_;
  std::unique_ptr<web::FoxgloveServer> foxglove_;
  static constexpr double kWebSamplesHz = 5.0;                   // scan samples sent so often
  static constexpr std::size_t kWebSamplesPerSensor = 20000;     // at most so many a sensor
  double web_samples_due_s_{0.0}, web_samples_wall_due_s_{0.0};  // --web's next samples
  double recorded_samples_due_s_{0.0};                           // RunHooks::web_state's
  static constexpr double kWebCameraHz = 2.0;  // camera frames a camera sent so often
  std::map<std::string, std::chrono::steady_clock::time_point> web_camera_due_;  // encoder thread
  std::mutex web_keys_mutex_;
  std::vector<ViewKey> web_keys_;  // --web-control's camera commands, not yet applied

  std::chrono::steady_clock::time_point start_;
  TickPacer pacer_{0.0, 0.0};
  std::int64_t tick_{0};
  double tick_time_s_{0.0};              // the last tick's time (lock-step: its input's)
  std::int64_t tick_utime_{0};           // and its clock, as inputs are stamped
  std::vector<bool> stale_, stale_now_;  // per robot and input: as last published, now
  CameraDirector::Shot shot_;
  bool recording_failure_reported_{false};
  InputClock input_clock_;  // lock-step time
  double next_status_s_{0.0}, next_progress_s_{0.0}, next_surfaces_s_{0.0};
  std::uint64_t surfaces_sent_revision_{0};
  std::int64_t origin_moves_{0};
  double longest_origin_move_ms_{0.0};
  RateSchedule scan_file_schedule_{options_.scans_every_s > 0.0 ? 1.0 / options_.scans_every_s
                                                                : 0.0};
};

}  // namespace sandbox::app
