#include "app/camera_director.h"

#include "sensors/render/debug_overlay.h"

namespace sandbox::app {

CameraDirector::CameraDirector(const scene::Level& level,
                               const std::vector<render::MountedCamera>& cameras)
    : level_(level) {
  for (const render::MountedCamera& camera : cameras) {
    runs_.push_back({&camera, render::ChaseCamera(camera.chase),
                     RateSchedule(camera.spec.rate_hz > 0.0 ? camera.spec.rate_hz : 30.0)});
  }
}

const std::string& CameraDirector::live_camera() const {
  return runs_.at(std::size_t(controls_.camera)).camera->spec.name;
}

void CameraDirector::FollowCameraChoice(const Shot& shot) {
  for (const bridge::RobotFeed* feed : shot.feeds) {
    const std::string& name = feed->active_camera();
    if (name.empty() || name == last_choice_) continue;
    last_choice_ = name;
    for (std::size_t c = 0; c < runs_.size(); ++c) {
      if (runs_[c].camera->spec.name == name) controls_.camera = int(c);
    }
  }
}

int CameraDirector::Direct(const Shot& shot, FramePipeline* frames, bool write, bool live) {
  FollowCameraChoice(shot);
  int submitted = 0;
  for (CameraRun& run : runs_) {
    const bool shown = live && &run == &runs_[std::size_t(controls_.camera)];
    const double dt = run.last_s < 0.0 ? 0.0 : shot.t_s - run.last_s;
    run.last_s = shot.t_s;
    const std::size_t robot = std::size_t(run.camera->robot);
    const scene::RobotState& state = *shot.robots[robot];
    // Steered from <ROBOT>/CAMERA and by the keys.
    const bridge::TrailingCommand& command = shot.feeds[robot]->trailing();
    render::TrailingCommand steer{command.pan_rad + controls_.steer.pan_rad,
                                  command.tilt_rad + controls_.steer.tilt_rad,
                                  command.zoom * controls_.steer.zoom};
    render::CameraView view = run.camera->view;
    view.X_WC = run.camera->Pose(state, &run.chase, steer, dt);  // the chase lag advances
    if (run.camera->kind == render::CameraKind::kTrailing) {
      view.fov_y_rad = render::ZoomedFov(view.fov_y_rad, steer.zoom);
    }
    if (frames == nullptr || (!write && !shown) || !run.schedule.Due(shot.t_s)) continue;
    run.schedule.Done(shot.t_s);
    RenderJob job;
    job.camera = run.camera->spec.name;
    job.tick = shot.tick;
    job.time_s = shot.t_s;
    job.utime = shot.utime;
    job.view = view;
    job.settings = run.camera->look;
    if (shown) job.settings.images |= render::kColorImage;  // the live view shows colour
    job.write = write;
    job.show = shown;
    for (scene::RobotState* r : shot.robots) {
      r->Skin();  // at most once a tick, however many cameras are due
      job.robots.push_back(*r);
    }
    for (std::size_t a = 0; a < level_.actors.size(); ++a) {
      job.actor_poses.push_back(shot.world->actor_pose(int(a)));
    }
    job.robot_pose = state.pose();
    job.terrain = shot.terrain;
    if (run.camera->overlay != (shown && controls_.overlay))
      AddOverlay(run, shot, &job);  // 'o' flips
    frames->Submit(std::move(job));
    ++submitted;
  }
  return submitted;
}

void CameraDirector::AddOverlay(const CameraRun& run, const Shot& shot, RenderJob* job) const {
  for (const sensors::Sensor& sensor : *shot.sensors) {
    if (sensor.mounted().robot != run.camera->robot) continue;
    if (const auto* scan = std::get_if<sensors::FaceScan>(&sensor.output())) {
      render::AddFaceScan(*scan, run.camera->overlay_stub_m, &job->overlay,
                          run.camera->overlay_colour);
    }
  }
  render::AddBoneFrames(*shot.robots[std::size_t(run.camera->robot)], 1.0, &job->overlay);
  render::AddActorBounds(level_, job->actor_poses, false, &job->overlay);
}

}  // namespace sandbox::app
