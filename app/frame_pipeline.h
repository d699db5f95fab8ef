#pragma once
// Camera frames off the loop thread: a render thread that owns the GL context
// renders the jobs the loop submits, and an encoder thread writes them with
// OpenCV. Both queues are small and bounded: when a stage is behind, a
// camera's newer job replaces its older one still waiting (so a 10 Hz camera
// is not starved by two 30 Hz ones on a busy machine), and the oldest job is
// dropped when the queue is full; drops are counted, and the loop never waits.
//
// Files: DIR/<camera>/<camera>_<tick>.jpg (or .png) and/or one
// DIR/<camera>.mp4 (or .avi) per camera; DIR/<camera>/<camera>_<tick>_depth.png
// (16-bit millimetres), _depth.npy or _depth.exr (float32 metres); _seg.png
// (16-bit segment ids, named in DIR/segmentation.csv); _normals.png (8-bit,
// camera frame) or _normals.npy with a float depth format; DIR/<camera>.csv
// indexing every frame: tick, time_s, file (the image, else the video; paths
// relative to DIR), the robot pose, the
// camera pose X_WC (x forward, y left, z up), the pinhole intrinsics in
// pixels (fx = fy, cx, cy; image x to the right, y down, pixel centres at
// whole coordinates as in OpenCV's camera matrix) and the files of the other
// image kinds (depth, segmentation, normals; empty when not made).

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "app/row_file.h"
#include "scene/level.h"
#include "scene/robot_state.h"
#include "sensors/render/renderer.h"

namespace sandbox::app {

struct FramePipelineConfig {
  std::string out_dir;              // empty: nothing written (a live view only)
  std::string image_format{"jpg"};  // jpg, png, or empty: no image files
  std::string video_format;         // mp4 (mp4v), avi (MJPG), or empty: no video
  std::string depth_format{"png"};  // png (16-bit millimetres), npy or exr (float32 metres)
  double video_fps{30.0};
  std::size_t queue_capacity{4};
  // Lock-step runs: Submit waits for room instead of dropping, so that every
  // due frame is written and a run's frames depend on its inputs alone.
  bool lossless{false};
  // Called on the render thread with each frame of a job marked `show`.
  std::function<void(const std::string& camera, const render::Frame& frame)> show;
  // Called on the encoder thread after each frame is written, with its
  // colour image's file (empty when none was written: a video only).
  std::function<void(const std::string& camera, std::int64_t tick, std::int64_t utime,
                     const render::CameraView& view, const render::Frame& frame,
                     const std::filesystem::path& color_file)>
      written;
};

// What the loop hands over: a camera view and copies of the robot states.
struct RenderJob {
  std::string camera;
  std::int64_t tick{0};
  double time_s{0.0};
  std::int64_t utime{0};  // the tick's clock, as inputs are stamped
  render::CameraView view;
  render::RenderSettings settings;  // the look and the image kinds
  std::vector<scene::RobotState> robots;
  std::vector<Eigen::Isometry3d> actor_poses;
  Eigen::Isometry3d robot_pose{Eigen::Isometry3d::Identity()};  // for the index
  render::Overlay overlay;                                      // empty: none
  std::shared_ptr<const scene::TileList> terrain;               // null: none
  bool write{true};                                             // to the output folder
  bool show{false};  // to FramePipelineConfig::show (the live view)
};

// A frame's intrinsics as the index has them: a lens's own, else a pinhole's
// (square pixels, the focal length from the vertical field of view, pixel
// centres at whole coordinates; no distortion).
render::Lens FrameIntrinsics(const render::CameraView& view);

class FramePipeline {
 public:
  // Starts both threads and returns once the renderer, made on the render
  // thread, has the level (or has failed: frames are then counted as failed).
  // Throws std::runtime_error when DIR cannot be created.
  FramePipeline(const scene::Level& level, const FramePipelineConfig& config);
  // Finishes what is queued, closes videos and indexes (also done by the destructor).
  void Finish();
  ~FramePipeline();
  FramePipeline(const FramePipeline&) = delete;
  FramePipeline& operator=(const FramePipeline&) = delete;

  // Loop thread: never blocks (unless the config is lossless).
  void Submit(RenderJob job);

  std::int64_t rendered() const { return rendered_; }
  std::int64_t written() const { return written_; }
  std::int64_t dropped() const { return dropped_render_ + dropped_write_; }
  std::int64_t failed() const { return failed_; }
  std::string error() const;  // the first failure, reported once

 private:
  struct Encoded {
    std::string camera;
    std::int64_t tick;
    double time_s;
    std::int64_t utime;
    render::Frame frame;
    Eigen::Isometry3d robot_pose;
    render::CameraView view;
  };
  void RenderLoop();
  void WriteLoop();
  void Write(const Encoded& item);
  void Fail(const std::string& what);  // counts; the first one is kept and printed

  const scene::Level& level_;
  FramePipelineConfig config_;
  mutable std::mutex mutex_;
  std::condition_variable render_wake_, write_wake_, room_;
  std::deque<RenderJob> render_queue_;
  std::deque<Encoded> write_queue_;
  bool stopping_{false};
  bool render_done_{false};   // the render thread has finished: the writer may stop
  bool render_ready_{false};  // the renderer has the level (or could not be made)
  std::atomic<std::int64_t> rendered_{0}, written_{0}, dropped_render_{0}, dropped_write_{0},
      failed_{0};
  std::string first_error_;
  struct Video;
  std::map<std::string, std::unique_ptr<Video>> videos_;     // write thread only
  std::map<std::string, std::unique_ptr<RowFile>> indexes_;  // write thread only
  std::chrono::steady_clock::time_point retry_after_{};      // write thread only
  bool legend_written_{false};                               // write thread only
  std::set<std::string> camera_dirs_;                        // made; write thread only
  std::thread render_thread_, write_thread_;
};

}  // namespace sandbox::app
