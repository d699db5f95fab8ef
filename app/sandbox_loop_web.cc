// SandboxLoop's part in the browser view (--web, and `sandbox view`'s
// recorded states): each tick's state and samples, and camera frames. The
// rest of the loop is in sandbox_loop.cc.

#include <chrono>

#include "app/command_line.h"
#include "app/images.h"
#include "app/sandbox_loop.h"
#include "app/web_samples.h"
#include "web/stream_state.h"

namespace sandbox::app {

using Clock = std::chrono::steady_clock;

void SandboxLoop::ShowCameraFrame(const std::string& camera, std::int64_t tick,
                                  const render::CameraView& view, const render::Frame& frame,
                                  const std::filesystem::path& color_file) {
  if (!web_ || web_->counts().clients == 0 || frame.rgb.empty()) return;
  const auto now = Clock::now();
  Clock::time_point& due = web_camera_due_[camera];
  if (now < due) return;
  due = now + std::chrono::milliseconds(int(1000.0 / kWebCameraHz));
  web::CameraFrame shown{camera, tick, view.X_WC, view.fov_y_rad, frame.width, frame.height, {}};
  std::string format;
  shown.jpeg = CompressedColor(frame, color_file, false, &format);  // the writer's own JPEG
  web_->SetCameraFrame(shown);
}

void SandboxLoop::PublishWebState(const TickRecord& record, double wall_s) {
  // Samples a few times a second of the run's time and of the wall's (a
  // replay runs faster than its clock: they are most of the bytes).
  const bool due = tick_time_s_ >= web_samples_due_s_ && wall_s >= web_samples_wall_due_s_;
  if (due) {
    web_samples_due_s_ = tick_time_s_ + 1.0 / kWebSamplesHz;
    web_samples_wall_due_s_ = wall_s + 1.0 / kWebSamplesHz;
  }
  web_->Publish([state = WebState(record, due)] {
    return web::EncodedState(web::EncodeState(state), web::EncodeSamples(state));
  });
}

web::StreamState SandboxLoop::WebState(const TickRecord& record, bool with_samples) {
  web::StreamState state;
  state.tick = record.tick;
  state.time_s = tick_time_s_;
  state.tick_ms = record.duration_ms;
  state.late_ms = record.lateness_ms;
  for (std::size_t r = 0; r < robots_.size(); ++r) {
    web::StreamState::Robot robot;
    robot.name = level_.robots[r].name;
    const bridge::RobotFeed& feed = *robots_[r].feed;
    robot.has_pose = feed.input().seq >= 0 || feed.input().utime >= 0;
    const Eigen::Isometry3d& X_WB = robots_[r].state->pose();
    robot.p_W = X_WB.translation();
    robot.q_W = Eigen::Quaterniond(X_WB.linear());
    const scene::RobotState& robot_state = *robots_[r].state;
    robot.bone_values = robot_state.bone_values();
    const std::vector<scene::SkinJoint>& joints = robot_state.model().joints;
    robot.joints.reserve(12 * joints.size());
    for (const scene::SkinJoint& joint : joints) {
      const Eigen::Matrix<double, 3, 4> X_BN =
          robot_state.node_poses_B()[std::size_t(joint.node)].matrix().topRows<3>();
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 4; ++j) robot.joints.push_back(X_BN(i, j));
    }
    for (const bridge::ChannelStatus& channel : feed.Channels(tick_utime_)) {
      robot.received += channel.received;
      robot.rejected += channel.rejected;
      if (channel.stale) robot.stale.push_back(channel.channel);
    }
    state.robots.push_back(std::move(robot));
  }
  for (std::size_t a = 0; a < level_.actors.size(); ++a) {
    if (!level_.actors[a].movable) continue;
    const Eigen::Isometry3d& X_WA = world_.actor_pose(int(a));
    state.actors.push_back(
        {level_.actors[a].name, X_WA.translation(), Eigen::Quaterniond(X_WA.linear())});
  }
  if (with_samples) {
    state.has_samples = true;
    state.samples_tick = state.tick;
    state.samples_origin = world_.origin();
    for (const sensors::Sensor& sensor : sensors_) {
      state.samples.push_back(ViewSamples(sensor,
                                          level_.robots[std::size_t(sensor.mounted().robot)].name,
                                          state.samples_origin, kWebSamplesPerSensor));
    }
  }
  return state;
}

}  // namespace sandbox::app
