#include "app/frame_pipeline.h"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "app/command_line.h"
#include "app/images.h"
#include "scene/surface_ids.h"

namespace sandbox::app {
namespace {

// Frames yield to the loop: on a machine with few cores the loop's wake-ups
// would otherwise wait behind rendering and encoding (Linux nice is per thread).
void LowerThisThreadsPriority() { setpriority(PRIO_PROCESS, id_t(syscall(SYS_gettid)), 10); }

// Queues a job or frame where the stage behind it may be late: a newer one of
// the same camera takes the older one's place (so every camera keeps its turn,
// however often the others come), else the oldest waiting one is dropped when
// the queue is full. Returns how many were dropped.
template <typename Item>
int PushNewestPerCamera(std::deque<Item>* queue, Item item, std::size_t capacity) {
  for (Item& waiting : *queue) {
    if (waiting.camera == item.camera) {
      waiting = std::move(item);
      return 1;
    }
  }
  int dropped = 0;
  if (queue->size() >= capacity) {
    queue->pop_front();
    dropped = 1;
  }
  queue->push_back(std::move(item));
  return dropped;
}

}  // namespace

struct FramePipeline::Video {
  cv::VideoWriter writer;
};

FramePipeline::FramePipeline(const scene::Level& level, const FramePipelineConfig& config)
    : level_(level), config_(config) {
  if (!config_.out_dir.empty()) CreateOutputFolder(config_.out_dir);
  render_thread_ = std::thread([this] { RenderLoop(); });
  write_thread_ = std::thread([this] { WriteLoop(); });
  // The context and the level's upload (tens of ms to seconds) before the
  // first tick, so that the first frames are not dropped while they happen.
  std::unique_lock<std::mutex> lock(mutex_);
  room_.wait(lock, [&] { return render_ready_; });
}

FramePipeline::~FramePipeline() { Finish(); }

void FramePipeline::Finish() {
  if (!render_thread_.joinable()) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  render_wake_.notify_all();
  render_thread_.join();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    render_done_ = true;
  }
  write_wake_.notify_all();
  write_thread_.join();
}

render::Lens FrameIntrinsics(const render::CameraView& view) {
  if (view.lens) return *view.lens;
  render::Lens lens;
  const double f = 0.5 * view.height / std::tan(0.5 * view.fov_y_rad);
  lens.fx = lens.fy = f, lens.cx = 0.5 * view.width - 0.5;
  lens.cy = 0.5 * view.height - 0.5;
  return lens;
}

void FramePipeline::Submit(RenderJob job) {
  {
    std::unique_lock<std::mutex> lock(mutex_);
    if (config_.lossless) {
      room_.wait(lock, [&] { return render_queue_.size() < config_.queue_capacity; });
      render_queue_.push_back(std::move(job));
    } else {
      dropped_render_ +=
          PushNewestPerCamera(&render_queue_, std::move(job), config_.queue_capacity);
    }
  }
  render_wake_.notify_one();
}

std::string FramePipeline::error() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return first_error_;
}

void FramePipeline::RenderLoop() {
  LowerThisThreadsPriority();  // before the context: llvmpipe's threads inherit it
  std::unique_ptr<render::Renderer> renderer;
  try {
    renderer = render::MakeRenderer();
    renderer->SetLevel(level_, OpenCvTextureDecoder(level_.limits));
    for (const std::string& warning : renderer->warnings())
      std::cerr << "sandbox: warning: " << warning << "\n";
  } catch (const std::exception& e) {
    Fail(std::string("cannot render: ") + e.what());
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    render_ready_ = true;
  }
  room_.notify_all();
  for (;;) {
    RenderJob job;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      render_wake_.wait(lock, [&] { return stopping_ || !render_queue_.empty(); });
      if (render_queue_.empty()) break;  // stopping and drained
      job = std::move(render_queue_.front());
      render_queue_.pop_front();
    }
    room_.notify_all();
    if (!renderer) {  // every frame fails alike: counted, reported once
      ++failed_;
      continue;
    }
    Encoded item{job.camera, job.tick, job.time_s, job.utime, {}, job.robot_pose, job.view};
    std::vector<const scene::RobotState*> robots;
    for (const scene::RobotState& state : job.robots) robots.push_back(&state);
    try {
      renderer->SetTerrain(job.terrain);
      renderer->Render(job.view, job.actor_poses, robots, job.settings, &item.frame, &job.overlay);
    } catch (const std::exception& e) {
      Fail("camera " + job.camera + ": " + e.what());
      continue;
    }
    ++rendered_;
    if (job.show && config_.show) config_.show(job.camera, item.frame);
    if (!job.write || config_.out_dir.empty()) continue;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      if (config_.lossless) {
        room_.wait(lock, [&] { return write_queue_.size() < config_.queue_capacity; });
        write_queue_.push_back(std::move(item));
      } else {
        dropped_write_ +=
            PushNewestPerCamera(&write_queue_, std::move(item), config_.queue_capacity);
      }
    }
    write_wake_.notify_one();
  }
}

void FramePipeline::WriteLoop() {
  LowerThisThreadsPriority();
  for (;;) {
    Encoded item;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      write_wake_.wait(lock, [&] { return !write_queue_.empty() || render_done_; });
      if (write_queue_.empty()) break;  // the render thread is done and all is written
      item = std::move(write_queue_.front());
      write_queue_.pop_front();
    }
    room_.notify_all();
    Write(item);
  }
  for (auto& [camera, video] : videos_) video->writer.release();
}

void FramePipeline::Write(const Encoded& item) {
  // After a failure (a full disk, say) writing pauses for a second: frames
  // meanwhile are counted as failed without trying, and without noise.
  const auto now = std::chrono::steady_clock::now();
  if (now < retry_after_) {
    ++failed_;
    return;
  }
  const std::filesystem::path dir = config_.out_dir;
  // A camera's images in a folder of its own: DIR/chase/chase_000017.jpg.
  std::ostringstream name;
  name << item.camera << "/" << item.camera << "_" << std::setw(6) << std::setfill('0')
       << item.tick;
  std::string file;
  try {
    if (camera_dirs_.insert(item.camera).second) {
      std::error_code error;
      std::filesystem::create_directories(dir / item.camera, error);
      if (error) {
        camera_dirs_.erase(item.camera);
        throw std::runtime_error("cannot make the folder " + (dir / item.camera).string() + ": " +
                                 error.message());
      }
    }
    if (!config_.video_format.empty()) {
      std::unique_ptr<Video>& video = videos_[item.camera];
      if (!video) {
        video = std::make_unique<Video>();
        file = (dir / (item.camera + "." + config_.video_format)).string();
        const int fourcc = config_.video_format == "mp4"
                               ? cv::VideoWriter::fourcc('m', 'p', '4', 'v')
                               : cv::VideoWriter::fourcc('M', 'J', 'P', 'G');
        video->writer.open(file, cv::CAP_FFMPEG, fourcc, config_.video_fps,
                           cv::Size(item.frame.width, item.frame.height));
        if (!video->writer.isOpened()) throw std::runtime_error("cannot open the video " + file);
      }
      cv::Mat rgb(item.frame.height, item.frame.width, CV_8UC3,
                  const_cast<std::uint8_t*>(item.frame.rgb.data()));
      cv::Mat bgr;
      cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
      video->writer.write(bgr);
      file = item.camera + "." + config_.video_format;
    }
    const render::ImageKinds kinds = item.frame.kinds;
    if (!config_.image_format.empty() && (kinds & render::kColorImage)) {
      file = name.str() + "." + config_.image_format;
      WriteColor(item.frame, (dir / file).string());
    }
    std::string depth_file, segmentation_file, normals_file;
    if (kinds & render::kDepthImage) {
      depth_file = name.str() + "_depth." + config_.depth_format;
      if (config_.depth_format == "npy") {
        WriteDepthNpy(item.frame, (dir / depth_file).string());
      } else if (config_.depth_format == "exr") {
        WriteDepthExr(item.frame, (dir / depth_file).string());
      } else {
        WriteDepthMillimetres(item.frame, (dir / depth_file).string());
      }
    }
    if (kinds & render::kSegmentationImage) {
      if (!legend_written_) {  // the legend depends on the level alone
        std::ofstream legend(dir / "segmentation.csv");
        legend << scene::SurfaceIds(level_).Csv();
        if (!legend.good())
          throw std::runtime_error("cannot write " + (dir / "segmentation.csv").string());
        legend_written_ = true;
      }
      segmentation_file = name.str() + "_seg.png";
      WriteSegmentation(item.frame, (dir / segmentation_file).string());
    }
    if (kinds & render::kNormalsImage) {
      const bool floats = config_.depth_format != "png";
      normals_file = name.str() + (floats ? "_normals.npy" : "_normals.png");
      if (floats) {
        WriteNormalsNpy(item.frame, (dir / normals_file).string());
      } else {
        WriteNormals(item.frame, (dir / normals_file).string());
      }
    }
    if (file.empty())
      file = !depth_file.empty()          ? depth_file
             : !segmentation_file.empty() ? segmentation_file
                                          : normals_file;
    std::unique_ptr<RowFile>& index = indexes_[item.camera];
    if (!index) {
      index = std::make_unique<RowFile>(
          (dir / (item.camera + ".csv")).string(),
          "tick,time_s,file,x,y,z,qw,qx,qy,qz,cam_x,cam_y,cam_z,cam_qw,cam_qx,cam_qy,cam_qz,"
          "fx,fy,cx,cy,depth_file,segmentation_file,normals_file,lens,k1,k2,k3,k4,p1,p2");
    }
    std::ostringstream row;
    row << std::setprecision(10);
    for (const Eigen::Isometry3d* X : {&item.robot_pose, &item.view.X_WC}) {
      const Eigen::Vector3d p = X->translation();
      const Eigen::Quaterniond q(X->linear());
      if (X == &item.robot_pose) row << item.tick << "," << item.time_s << "," << file;
      row << "," << p.x() << "," << p.y() << "," << p.z() << "," << q.w() << "," << q.x() << ","
          << q.y() << "," << q.z();
    }
    // A pinhole: square pixels, one focal length from the vertical field of
    // view; pixel centres at whole coordinates, as OpenCV's camera matrix has
    // them. A lens: its own, and its coefficients (OpenCV's).
    const render::Lens lens = FrameIntrinsics(item.view);
    row << "," << lens.fx << "," << lens.fy << "," << lens.cx << "," << lens.cy << "," << depth_file
        << "," << segmentation_file << "," << normals_file << ","
        << (item.view.lens ? lens.ModelName() : "pinhole");
    for (const double k : {lens.k1, lens.k2, lens.k3, lens.k4, lens.p1, lens.p2}) row << "," << k;
    // The row is the frame's last part: a frame whose row cannot be written is removed.
    index->Add(row.str());
    if (!index->Flush()) throw std::runtime_error(index->error());
    ++written_;
    if (config_.written) {
      const bool color = !config_.image_format.empty() && (kinds & render::kColorImage);
      config_.written(
          item.camera, item.tick, item.utime, item.view, item.frame,
          color ? dir / (name.str() + "." + config_.image_format) : std::filesystem::path());
    }
  } catch (const std::exception& e) {
    Fail(e.what());
    retry_after_ = now + std::chrono::seconds(1);
    std::error_code ignored;  // no truncated files left behind
    if (!config_.image_format.empty()) {
      std::filesystem::remove(dir / (name.str() + "." + config_.image_format), ignored);
    }
    for (const char* other :
         {"_depth.png", "_depth.npy", "_depth.exr", "_seg.png", "_normals.png", "_normals.npy"}) {
      std::filesystem::remove(dir / (name.str() + other), ignored);
    }
  }
}

void FramePipeline::Fail(const std::string& what) {
  if (failed_++ > 0) return;
  std::lock_guard<std::mutex> lock(mutex_);
  first_error_ = what;
  std::cerr << "sandbox: frames: " << what << " (further failures are only counted)\n";
}

}  // namespace sandbox::app
