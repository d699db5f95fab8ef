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
//     the plain, fast and high presets (colour, as chase cameras write;
//     shaded forward, the reference for deferred shading; with depth;
//     without levels of detail), and each image kind, against the plain look
//     in the same run (ratio); the looks take turns a frame at a time.
//
//   bench_render [--seconds S] [--looks [--rounds N] [--only NAME]]
//   (sections 1 to 3; --looks: section 4 alone; --only: the look of that row
//   name alone, beside plain colour: a quick A/B or a profile of one look)

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <deque>
#include <filesystem>
#include <map>
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
#include "sensors/render/deferred_shading.h"
#include "sensors/render/renderer.h"

namespace {

using namespace sandbox;
using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

// The looks: each row renders the sample level's chase view (the wing posed
// mid-turn) with its settings; the rows take turns a frame at a time, so that
// the machine's slow and fast moments fall on all of them. Rows share a
// renderer where its state (the levels of detail each mesh was last drawn
// at) comes out the same: frames of colour alone at one allowance, frames
// with measurement images, and a moving row each its own.
// With `step_m`, the row's wing and camera move that far along x each frame.
struct LookRow {
  std::string name;
  render::RenderSettings settings;
  double step_m{0.0};
  render::Renderer* renderer{nullptr};
  scene::RobotState wing;
  render::ChaseCamera chase;
  render::CameraView view;
  std::vector<double> ms;
};

int BenchLooks(int rounds, const std::string& only) {
  const scene::Level level =
      scene::LoadLevel(std::string(SANDBOX_SOURCE_DIR) + "/assets/sample/level.toml");
  scene::RobotState wing(level.robots[0]);
  wing.SetPose(Eigen::Translation3d(-40, -30, 25) *
               Eigen::AngleAxisd(0.6, Eigen::Vector3d::UnitZ()));
  wing.Update();
  using render::Quality;
  auto look = [](Quality quality, render::ImageKinds kinds, float lod_px = 1.f) {
    render::RenderSettings settings = render::RenderSettings::Preset(quality);
    settings.images = kinds;
    settings.lod_px = lod_px;
    return settings;
  };
  const render::ImageKinds color(render::kColorImage);
  const render::ImageKinds color_depth(render::kColorImage | render::kDepthImage);
  std::vector<std::pair<std::string, render::RenderSettings>> settings;
  std::vector<double> steps;
  std::vector<std::string> names;
  auto add = [&](const std::string& name, const render::RenderSettings& s, double step_m = 0.0) {
    names.push_back(name);
    // --only NAME: that row alone after the first (plain colour, the ratios' base).
    if (!settings.empty() && !only.empty() && name != only) return;
    settings.emplace_back(name, s);
    steps.push_back(step_m);
  };
  // The looks as a chase camera writes them (colour), then shaded forward
  // (as drawn: the reference deferred shading replaces), with depth (drawn as
  // given: no levels of detail) and without levels of detail.
  for (const auto& [name, quality] :
       {std::pair{"plain", Quality::kPlain}, std::pair{"fast", Quality::kFast},
        std::pair{"high", Quality::kHigh}}) {
    add(std::string(name) + " (color)", look(quality, color));
  }
  for (const auto& [name, quality] :
       {std::pair{"plain", Quality::kPlain}, std::pair{"fast", Quality::kFast},
        std::pair{"high", Quality::kHigh}}) {
    render::RenderSettings every_face = look(quality, color);
    every_face.cull_hidden_back_faces = false;
    add(std::string(name) + ", every back face drawn", every_face);
  }
  for (const auto& [name, quality] :
       {std::pair{"fast", Quality::kFast}, std::pair{"high", Quality::kHigh}}) {
    render::RenderSettings forward = look(quality, color);
    forward.deferred = false;
    add(std::string(name) + ", shaded forward", forward);
  }
  for (const auto& [name, quality] :
       {std::pair{"plain", Quality::kPlain}, std::pair{"fast", Quality::kFast},
        std::pair{"high", Quality::kHigh}}) {
    add(std::string(name) + " (color, depth)", look(quality, color_depth));
    add(std::string(name) + " (color), no levels of detail", look(quality, color, 0.f));
  }
  render::RenderSettings fast_shadows = look(Quality::kFast, color);
  fast_shadows.shadows = true;
  add("fast + shadows", fast_shadows);
  render::RenderSettings fast_fxaa = look(Quality::kFast, color);
  fast_fxaa.fxaa = true;
  add("fast + FXAA", fast_fxaa);
  render::RenderSettings fast_msaa = look(Quality::kFast, color);
  fast_msaa.msaa_samples = 4;
  add("fast + 4x multisampling", fast_msaa);
  add("high, flying 10 m a frame", look(Quality::kHigh, color), 10.0);
  for (const auto& [name, kinds] :
       {std::pair{"high: + segmentation",
                  render::ImageKinds(render::kColorImage | render::kSegmentationImage)},
        std::pair{"high: all four",
                  render::ImageKinds(render::kColorImage | render::kDepthImage |
                                     render::kSegmentationImage | render::kNormalsImage)},
        std::pair{"depth only", render::ImageKinds(render::kDepthImage)},
        std::pair{"segmentation only", render::ImageKinds(render::kSegmentationImage)}}) {
    add(name, look(Quality::kHigh, kinds));
  }
  if (!only.empty() && settings.size() == 1 && only != names.front()) {
    std::fprintf(stderr, "bench_render: --only '%s' names no look; the looks are:\n", only.c_str());
    for (const std::string& name : names) std::fprintf(stderr, "  %s\n", name.c_str());
    return 2;
  }
  std::printf(
      "looks: sample level, chase camera, wing mid-turn; the rows take turns a frame at a "
      "time, %d rounds after 3 of warm-up;\nmedian ms a frame (fps), ratio to plain at that "
      "size; deferred shading kernel: %s\n",
      rounds, render::DeferredShader().kernel().c_str());
  std::printf("%-10s %-34s %10s %8s %8s\n", "size", "look", "ms", "fps", "ratio");
  for (const auto& [width, height] : {std::pair{640, 480}, std::pair{1280, 720}}) {
    std::vector<LookRow> rows;
    std::map<std::string, std::unique_ptr<render::Renderer>> renderers;
    for (std::size_t i = 0; i < settings.size(); ++i) {
      const render::RenderSettings& s = settings[i].second;
      const std::string group = steps[i] > 0.0                    ? settings[i].first
                                : s.images == render::kColorImage ? std::to_string(s.lod_px)
                                                                  : "measurements";
      std::unique_ptr<render::Renderer>& renderer = renderers[group];
      if (!renderer) {
        renderer = render::MakeRenderer();
        renderer->SetLevel(level, {});
      }
      LookRow row{settings[i].first,
                  settings[i].second,
                  steps[i],
                  renderer.get(),
                  wing,
                  render::ChaseCamera({}),
                  {},
                  {}};
      row.view.width = width;
      row.view.height = height;
      row.view.X_WC = row.chase.Update(row.wing.pose(), 0.0);
      rows.push_back(std::move(row));
    }
    render::Frame frame;
    for (int round = 0; round < rounds + 3; ++round) {
      for (LookRow& row : rows) {
        if (row.step_m > 0.0) {
          row.wing.SetPose(Eigen::Translation3d(row.step_m, 0, 0) * row.wing.pose());
          row.wing.Update();
          row.view.X_WC = row.chase.Update(row.wing.pose(), 1.0 / 30.0);
        }
        const auto start = Clock::now();
        row.renderer->Render(row.view, {}, {&row.wing}, row.settings, &frame);
        // (The first frames of a look compile its shaders.)
        if (round >= 3) {
          row.ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
        }
      }
    }
    const double plain_ms = bench::Median(rows.front().ms);
    for (const LookRow& row : rows) {
      const double ms = bench::Median(row.ms);
      std::printf("%4dx%-5d %-34s %10.2f %8.1f %7.2fx\n", width, height, row.name.c_str(), ms,
                  1e3 / ms, ms / plain_ms);
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = 5.0;
  bool looks_only = false;
  int rounds = 15;
  std::string only;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--seconds") && i + 1 < argc) seconds = std::atof(argv[++i]);
    if (!std::strcmp(argv[i], "--looks")) looks_only = true;
    if (!std::strcmp(argv[i], "--rounds") && i + 1 < argc) rounds = std::atoi(argv[++i]);
    if (!std::strcmp(argv[i], "--only") && i + 1 < argc) only = argv[++i];
  }
  std::printf("%s\n", bench::Machine().c_str());
  if (looks_only) return BenchLooks(std::max(rounds, 1), only);
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
