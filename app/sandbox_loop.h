#pragma once
// The loop of `sandbox run` (../shared/DESIGN.md, "One tick of the loop"):
// each tick drains the inputs (the newest message per channel; in lock-step
// the next pose), applies poses, bones and placements, runs the sensors that
// are due and publishes their outputs and the robot state, hands the cameras
// that are due to the render thread, publishes the status heartbeat once a
// second, and records the tick. A late tick is followed at once by the next;
// ticks are never bunched to catch up.
//
// Threads: everything here runs on the loop thread (the caller of Run). It
// starts the render and encoder threads (FramePipeline) and the scan-file
// writer, and takes real-time priority for itself when asked and allowed. The
// live view's window is run by the caller on the main thread.

#include <memory>
#include <ostream>
#include <string>
#include <variant>
#include <vector>

#include "app/frame_pipeline.h"
#include "app/live_view.h"
#include "app/loaded_level.h"
#include "app/pose_history.h"
#include "app/rate_schedule.h"
#include "app/run_hooks.h"
#include "app/run_options.h"
#include "app/scan_files.h"
#include "app/tick_stats.h"
#include "bridge/lcm_link.h"
#include "bridge/outputs.h"
#include "bridge/reject_log.h"
#include "bridge/robot_inputs.h"
#include "bridge/udp_inputs.h"
#include "scene/collision_world.h"
#include "scene/level.h"
#include "sensors/robot_sensors.h"

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
  // Any thread: ends Run() after the current tick.
  static void RequestStop();
  // The live view when asked for (its window is the caller's to run), or null.
  LiveView* live_view() { return live_view_.get(); }

 private:
  // A robot with its state, inputs and outputs.
  struct RobotRun {
    bridge::RobotBridgeConfig config;
    std::unique_ptr<scene::RobotState> state;
    std::unique_ptr<bridge::RobotInputs> inputs;
    std::unique_ptr<bridge::NetFdmInput> net_fdm;
    std::unique_ptr<bridge::DoublesInput> doubles;
    std::unique_ptr<bridge::RobotOutputs> outputs;
    bridge::InputTag input;  // the input the outputs are tagged with
    PoseHistory history;     // its poses over the longest lidar sweep
    int face_run{-1};        // its first face scanner in sensor_runs_, or -1

    // Every input's counters: the LCM channels, then the UDP sockets.
    std::vector<bridge::ChannelStatus> Channels(std::int64_t now_utime) const;
  };
  struct SensorRun {
    const sensors::MountedSensor* mounted;
    // The sensor, made once from its config (range sensors use the config itself).
    std::variant<std::monostate, sensors::FaceScanner, sensors::GroundScanner, sensors::Lidar>
        sensor;
    RateSchedule schedule;
    sensors::FaceScan face_scan;  // the latest, faces as last scanned
  };
  struct CameraRun {
    const sensors::MountedCamera* camera;
    sensors::ChaseCamera chase;
    RateSchedule schedule;
    double last_s{-1.0};
  };

  // Lock-step: makes the next pose available (reading the replayed log up to
  // it). False: stop (the log has ended); *wait: nothing yet, try again.
  bool NextLockstepInput(double wall_s, bool* wait);
  // Applies the inputs; returns the tick's time (input time in lock-step) and
  // sets *now_utime to the time stamp outputs carry.
  double ApplyInputs(double wall_s, double drain_budget_s, std::int64_t* now_utime,
                     TickRecord* record);
  void RunDueSensors(double t, std::int64_t now_utime);
  // Each robot's STATE, with its first face scanner's face frames.
  void PublishStates(std::int64_t now_utime);
  // Moves the floating origin to the first robot when it is far from it.
  void KeepOriginNearRobot();
  void WriteDueScans(double t);
  void SubmitDueFrames(double t, TickRecord* record);
  // Once a second, and at once when an input turns stale or fresh.
  void PublishStatusIfDue(double t, std::int64_t now_utime);
  // Says once that the recording (--record) could not be written.
  void ReportRecordingFailure();
  void PrintSummary(double elapsed_s);
  bool has_pose() const;

  const RunOptions options_;
  const RunHooks hooks_;
  std::ostream& out_;
  std::ostream& err_;
  const LoadedLevel loaded_;
  const scene::Level& level_{loaded_.level};
  const std::vector<sensors::MountedSensor>& mounted_{loaded_.sensors};
  const std::vector<sensors::MountedCamera>& cameras_{loaded_.cameras};
  scene::CollisionWorld world_;
  std::unique_ptr<bridge::LogReader> log_;
  bridge::LcmLink link_;
  sensors::RayCaster caster_;
  bridge::RejectLog reject_log_;
  std::vector<RobotRun> robots_;
  std::vector<SensorRun> sensor_runs_;
  std::vector<CameraRun> camera_runs_;
  ScanFileWriter scan_files_;
  TickStats stats_;
  std::unique_ptr<LiveView> live_view_;  // before frames_: frames_ calls into it
  ViewControls controls_;
  std::string last_active_camera_;
  bool write_frames_{false};
  std::unique_ptr<FramePipeline> frames_;

  std::int64_t tick_{0};
  std::vector<bool> stale_;  // per robot and input, as last published
  bool recording_failure_reported_{false};
  bool output_lost_{false};
  std::int64_t first_input_utime_{-1};
  double next_status_s_{0.0}, next_progress_s_{0.0};
  std::int64_t origin_moves_{0};
  double longest_origin_move_ms_{0.0};
  RateSchedule scan_file_schedule_{options_.scans_every_s > 0.0 ? 1.0 / options_.scans_every_s
                                                                : 0.0};
};

}  // namespace sandbox::app
