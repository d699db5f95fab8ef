// Rendering figures with OSMesa (llvmpipe):
//  1. A chase camera 640 x 480 on the sample level with the flying wing
//     flexing, rendered on its own thread and JPEG-encoded on another, free
//     running: frames per second, against the same render without encoding.
//  2. Render time against triangle count (generated terrains of 10k, 100k and
//     1M triangles), against an empty level as the reference; and the 1M
//     terrain seen from its middle along the ground, where culling works.
//
//  3. The overlay's cost.
//  4. The looks: the sample level's chase view at 640x480 and 1280x720 with
//     the plain, fast and high presets (colour, as chase cameras write; with
//     depth; without levels of detail), and each image kind, against the
//     plain look in the same run (ratio).
//
//   bench_render [--seconds S] [--looks]   (--looks: section 4 only)

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <deque>
#include <filesystem>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <thread>

#include "bench/bench_levels.h"
#include "scene/collision_world.h"
#include "scene/level.h"
#include "sensors/face_scanner.h"
#include "sensors/render/cameras.h"
#include "sensors/render/debug_overlay.h"
#include "sensors/render/renderer.h"

namespace {

using namespace sandbox;
using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

// Median milliseconds a frame of the sample level's chase view (the wing
// posed mid-turn) with `settings` at `width` x `height`, after a warm-up;
// with `step_m`, the wing and its camera move that far along x each frame.
double ChaseFrameMs(render::Renderer& renderer, scene::RobotState wing, int width, int height,
                    const render::RenderSettings& settings, double step_m = 0.0) {
  render::CameraView view;
  view.width = width;
  view.height = height;
  render::ChaseCamera chase({});
  render::Frame frame;
  std::vector<double> ms;
  for (int i = 0; i < 13; ++i) {
    if (i == 0 || step_m > 0.0) {
      wing.SetPose(Eigen::Translation3d(step_m, 0, 0) * wing.pose());
      wing.Update();
      view.X_WC = chase.Update(wing.pose(), i == 0 ? 0.0 : 1.0 / 30.0);
    }
    const auto start = Clock::now();
    renderer.Render(view, {}, {&wing}, settings, &frame);
    if (i >= 3)  // the first frames of a look compile its shaders
      ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
  }
  return bench::Median(ms);
}

int BenchLooks() {
  const scene::Level level =
      scene::LoadLevel(std::string(SANDBOX_SOURCE_DIR) + "/assets/sample/level.toml");
  auto renderer = render::MakeRenderer();
  renderer->SetLevel(level, {});
  scene::RobotState wing(level.robots[0]);
  wing.SetPose(Eigen::Translation3d(-40, -30, 25) *
               Eigen::AngleAxisd(0.6, Eigen::Vector3d::UnitZ()));
  wing.Update();
  std::printf(
      "looks: sample level, chase camera, wing mid-turn; median ms a frame (fps), ratio "
      "to plain at that size\n");
  std::printf("%-10s %-34s %10s %8s %8s\n", "size", "look", "ms", "fps", "ratio");
  for (const auto& [width, height] : {std::pair{640, 480}, std::pair{1280, 720}}) {
    double plain_ms = 0.0;
    auto row = [&](const std::string& name, const render::RenderSettings& settings,
                   double step_m = 0.0) {
      const double ms = ChaseFrameMs(*renderer, wing, width, height, settings, step_m);
      if (plain_ms == 0.0) plain_ms = ms;
      std::printf("%4dx%-5d %-34s %10.2f %8.1f %7.2fx\n", width, height, name.c_str(), ms, 1e3 / ms,
                  ms / plain_ms);
    };
    using render::Quality;
    // The looks as a chase camera writes them (colour), then with depth (drawn
    // as given: no levels of detail) and without levels of detail.
    auto look = [](Quality quality, render::ImageKinds kinds, float lod_px = 1.f) {
      render::RenderSettings settings = render::RenderSettings::Preset(quality);
      settings.images = kinds;
      settings.lod_px = lod_px;
      return settings;
    };
    const render::ImageKinds color(render::kColorImage);
    const render::ImageKinds color_depth(render::kColorImage | render::kDepthImage);
    for (const auto& [name, quality] :
         {std::pair{"plain", Quality::kPlain}, std::pair{"fast", Quality::kFast},
          std::pair{"high", Quality::kHigh}}) {
      row(std::string(name) + " (color)", look(quality, color));
    }
    for (const auto& [name, quality] :
         {std::pair{"plain", Quality::kPlain}, std::pair{"fast", Quality::kFast},
          std::pair{"high", Quality::kHigh}}) {
      row(std::string(name) + " (color, depth)", look(quality, color_depth));
      row(std::string(name) + " (color), no levels of detail", look(quality, color, 0.f));
    }
    render::RenderSettings shadows = look(Quality::kFast, color);
    shadows.shadows = true;
    row("fast + shadows", shadows);
    render::RenderSettings msaa = look(Quality::kFast, color);
    msaa.msaa_samples = 4;
    row("fast + 4x multisampling", msaa);
    render::RenderSettings fxaa = look(Quality::kFast, color);
    fxaa.fxaa = true;
    row("fast + FXAA", fxaa);
    render::RenderSettings high_msaa = look(Quality::kHigh, color);
    high_msaa.fxaa = false;
    high_msaa.msaa_samples = 4;
    row("high with 4x MSAA for FXAA", high_msaa);
    row("high, flying 10 m a frame", look(Quality::kHigh, color), 10.0);
    for (const auto& [name, kinds] :
         {std::pair{"high: + segmentation",
                    render::ImageKinds(render::kColorImage | render::kSegmentationImage)},
          std::pair{"high: + normals",
                    render::ImageKinds(render::kColorImage | render::kNormalsImage)},
          std::pair{"high: all four",
                    render::ImageKinds(render::kColorImage | render::kDepthImage |
                                       render::kSegmentationImage | render::kNormalsImage)},
          std::pair{"depth only", render::ImageKinds(render::kDepthImage)},
          std::pair{"segmentation only", render::ImageKinds(render::kSegmentationImage)}}) {
      row(name, look(Quality::kHigh, kinds));
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = 5.0;
  bool looks_only = false;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--seconds") && i + 1 < argc) seconds = std::atof(argv[++i]);
    if (!std::strcmp(argv[i], "--looks")) looks_only = true;
  }
  if (looks_only) return BenchLooks();
  // 1. Chase camera, render thread + encoder thread.
  {
    const scene::Level level =
        scene::LoadLevel(std::string(SANDBOX_SOURCE_DIR) + "/assets/sample/level.toml");
    std::mutex mutex;
    std::condition_variable wake;
    std::deque<render::Frame> queue;
    std::atomic<bool> done{false};
    std::atomic<long> rendered{0}, encoded{0};
    std::size_t bytes = 0;
    std::thread encoder([&] {
      std::vector<std::uint8_t> jpeg;
      for (;;) {
        render::Frame frame;
        {
          std::unique_lock<std::mutex> lock(mutex);
          wake.wait(lock, [&] { return done || !queue.empty(); });
          if (queue.empty()) break;
          frame = std::move(queue.front());
          queue.pop_front();
        }
        cv::Mat rgb(frame.height, frame.width, CV_8UC3, frame.rgb.data()), bgr;
        cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
        cv::imencode(".jpg", bgr, jpeg);
        bytes = jpeg.size();
        ++encoded;
      }
    });
    auto renderer = render::MakeRenderer();
    renderer->SetLevel(level, {});
    scene::RobotState wing(level.robots[0]);
    render::ChaseCamera chase({});
    render::CameraView view;
    const auto start = Clock::now();
    double render_only_s = 0.0;
    for (int i = 0;; ++i) {
      const double t = std::chrono::duration<double>(Clock::now() - start).count();
      if (t >= seconds) break;
      // The wing circles and flexes, as the example model flies it.
      const double a = 0.125 * i * 0.033;
      Eigen::Isometry3d X = Eigen::Translation3d(120 * std::cos(a), 120 * std::sin(a), 60) *
                            Eigen::AngleAxisd(a + M_PI / 2, Eigen::Vector3d::UnitZ());
      wing.SetPose(X);
      for (int b = 1; b <= 20; ++b) {
        const double values[2] = {(b <= 10 ? 1 : -1) * 0.06 * std::sin(0.05 * i), 0.0};
        wing.SetBone(b, values, 2);
      }
      wing.Update();
      view.X_WC = chase.Update(X, 0.033);
      render::Frame frame;
      const auto render_start = Clock::now();
      renderer->Render(view, {}, {&wing}, {}, &frame);
      render_only_s += std::chrono::duration<double>(Clock::now() - render_start).count();
      ++rendered;
      {
        std::lock_guard<std::mutex> lock(mutex);
        if (queue.size() >= 2) queue.pop_front();  // drop the oldest, as the writer does
        queue.push_back(std::move(frame));
      }
      wake.notify_one();
    }
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    done = true;
    wake.notify_one();
    encoder.join();
    std::printf(
        "chase 640x480, sample level + flying wing: %.1f frames/s rendered and JPEG-encoded "
        "(%.1f rendered/s; render alone %.2f ms a frame = %.0f fps), %zu KB a JPEG; target 80\n",
        encoded / elapsed, rendered / elapsed, 1e3 * render_only_s / double(rendered.load()),
        double(rendered.load()) / render_only_s, bytes / 1024);
  }
  // 2. Render time against triangles.
  {
    const fs::path dir = fs::temp_directory_path() / "sandbox-bench-render";
    fs::create_directories(dir);
    std::printf("\n%-12s %12s %14s %8s\n", "triangles", "render ms", "empty-level ms", "ratio");
    double empty_ms = 0.0;
    for (const int triangles : {0, 10000, 100000, 1000000}) {
      std::unique_ptr<render::Renderer> renderer = render::MakeRenderer();
      scene::Level level;
      if (triangles > 0) {
        const int side = int(std::sqrt(triangles / 2.0));  // a square about the origin
        level = scene::LoadLevel(bench::WriteTerrainLevel(
            dir, "terrain" + std::to_string(triangles), side, side, -side / 2, -side / 2));
        renderer->SetLevel(level, {});
      } else {
        renderer->SetLevel(level, {});
      }
      auto median_ms = [&](const Eigen::Isometry3d& X_WC) {
        render::CameraView view;
        view.X_WC = X_WC;
        std::vector<double> ms;
        render::Frame frame;
        for (int i = 0; i < 21; ++i) {
          const auto start = Clock::now();
          renderer->Render(view, {}, {}, {}, &frame);
          if (i > 0)
            ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
        }
        return bench::Median(ms);
      };
      // All of the terrain in view.
      const double median =
          median_ms(render::LookAt(Eigen::Vector3d(-200, -200, 150), Eigen::Vector3d(0, 0, 0)));
      if (triangles == 0) empty_ms = median;
      std::printf("%-12d %12.2f %14.2f %7.1fx\n", int(level.num_triangles()), median, empty_ms,
                  median / empty_ms);
      if (triangles == 1000000) {
        // From the middle along the ground: about a sixth of the terrain in the
        // frustum, the rest culled by 128 m cells.
        const double ground =
            median_ms(render::LookAt(Eigen::Vector3d(0, 0, 10), Eigen::Vector3d(100, 0, 0)));
        std::printf("%-12s %12.2f %14s %7.2fx of seeing it all (culling)\n", "1M, ground", ground,
                    "", ground / median);
      }
    }
    fs::remove_all(dir);
  }
  // 3. The overlay's cost.
  {
    const scene::Level level =
        scene::LoadLevel(std::string(SANDBOX_SOURCE_DIR) + "/assets/sample/level.toml");
    const scene::CollisionWorld world(level);
    sensors::RayCaster caster;
    sensors::FaceScannerConfig config;
    config.refresh = sensors::Refresh::kFull;
    const sensors::FaceScanner scanner(config);
    sensors::FaceScan scan = scanner.EmptyScan();
    scene::RobotState wing(level.robots[0]);
    wing.SetPose(Eigen::Isometry3d(Eigen::Translation3d(0, 0, 12)));
    wing.Update();
    sensors::RayFilter filter;
    filter.ignore_robot = 0;
    scanner.Scan(world, caster, filter, wing.pose(), 0, &scan);
    render::Overlay points, stubs, rays;
    render::AddFaceScan(scan, 0.0, &points);
    render::AddFaceScan(scan, 0.5, &stubs);
    render::AddFaceScan(scan, 100.0, &rays);
    auto renderer = render::MakeRenderer();
    renderer->SetLevel(level, {});
    render::CameraView view;
    view.X_WC = render::TrailingPose(wing.pose(), 25.0, 8.0, {});
    auto median_ms = [&](const render::Overlay* overlay) {
      std::vector<double> ms;
      render::Frame frame;
      for (int i = 0; i < 21; ++i) {
        const auto start = Clock::now();
        renderer->Render(view, {}, {&wing}, {}, &frame, overlay);
        if (i > 0)
          ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
      }
      return bench::Median(ms);
    };
    const double plain = median_ms(nullptr);
    std::printf("\noverlay, trailing 640x480, %zu samples: plain %.2f ms", points.points_W.size(),
                plain);
    for (const auto& [name, overlay] :
         {std::pair<const char*, const render::Overlay*>{"points", &points},
          {"0.5 m stubs", &stubs},
          {"whole rays", &rays}}) {
      const double ms = median_ms(overlay);
      std::printf(", %s %.2f ms (%.2fx)", name, ms, ms / plain);
    }
    std::printf("\n");
  }
  return 0;
}
