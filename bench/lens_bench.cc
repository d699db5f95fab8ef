// A lens remap's cost (sensors/render/lens.h): a 640 x 480 frame gathered
// through a Brown-Conrady and a fisheye lens from their pinhole source frames
// (twice the lens's density), straight from the source's read-back as GL
// gives it: the colour image alone (the budget of 1 ms) and all four
// images (colour, depth, segmentation, normals), each on a pool of two
// threads as the renderer runs it and on one; beside a plain copy of the
// source's four images (the reference, in the same process); and the map's
// one-off build. Medians of runs in turns. The source's own render is not
// counted there; a second table gives whole frames through each lens on the
// sample level against the same camera as a pinhole (the reference).
//
//   bench_lens [--seconds S]   (time per figure, default 1)

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "bench/bench_levels.h"
#include "scene/level.h"
#include "sensors/render/lens.h"
#include "sensors/render/renderer.h"

namespace {

using namespace sandbox;
using Clock = std::chrono::steady_clock;

// A source's four images as the renderer reads them back (rows bottom
// first, colour RGBA, the raw depth buffer), and a copy of them.
struct SourceImages {
  std::vector<std::uint8_t> rgba;
  std::vector<float> depth, normal;
  std::vector<std::uint32_t> segment;

  explicit SourceImages(const render::CameraView& source) {
    const std::size_t n = std::size_t(source.width) * std::size_t(source.height);
    rgba.resize(4 * n), depth.resize(n), segment.resize(n), normal.resize(3 * n);
    for (std::size_t i = 0; i < n; ++i) {
      rgba[4 * i] = std::uint8_t(i), rgba[4 * i + 1] = std::uint8_t(i >> 3);
      rgba[4 * i + 2] = std::uint8_t(i >> 6), rgba[4 * i + 3] = 255;
      depth[i] = float(i % 1000) / 1000.f, segment[i] = std::uint32_t(i % 7);
      normal[3 * i + 2] = 1.0f;
    }
  }
  render::RawImages Raw(const render::CameraView& source, bool color_only) const {
    render::RawImages raw;
    raw.width = source.width, raw.height = source.height;
    raw.rgba = rgba.data();
    if (!color_only) {
      raw.depth = depth.data(), raw.segment = segment.data(), raw.normal = normal.data();
      raw.near_m = source.near_m, raw.far_m = source.far_m;
    }
    return raw;
  }
};

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = 1.0;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--seconds") == 0 && i + 1 < argc) {
      seconds = std::max(0.05, std::atof(argv[++i]));
    } else {
      std::fprintf(stderr, "usage: bench_lens [--seconds S]\n");
      return 2;
    }
  }
  std::printf("%s\n", bench::Machine().c_str());
  render::Lens brown;
  brown.fx = 520.0, brown.fy = 515.0, brown.cx = 321.5, brown.cy = 238.25;
  brown.k1 = -0.28, brown.k2 = 0.09, brown.k3 = -0.01, brown.p1 = 0.0012, brown.p2 = -0.0008;
  render::Lens fisheye;
  fisheye.model = render::Lens::Model::kFisheye;
  fisheye.fx = fisheye.fy = 330.0, fisheye.cx = 319.5, fisheye.cy = 239.5;
  fisheye.k1 = 0.02, fisheye.k2 = -0.004, fisheye.k3 = 0.001, fisheye.k4 = -0.0002;
  render::CameraView view;
  view.width = 640, view.height = 480;
  std::printf("%-14s %10s %7s %8s %10s %10s %9s %9s %8s %8s\n", "lens, 640x480", "source px",
              "map ms", "copy ms", "colour ms", "colour 1t", "all4 ms", "all4 1t", "all4/cp",
              "colour/1ms");
  sensors::WorkerPool pool(2);
  for (const auto& [name, lens] : {std::pair{"brown_conrady", brown}, {"fisheye", fisheye}}) {
    const render::CameraView source = render::SourceView(view, lens);
    const auto built = Clock::now();
    const render::LensRemap remap(lens, view.width, view.height, source);
    const double map_s = Seconds(built);
    const SourceImages from(source);
    SourceImages copy = from;
    render::Frame out;
    // Per figure: colour and all four, on two threads and on one; the copy.
    std::vector<double> times[5];
    const auto start = Clock::now();
    // Each remap right after its source is written, as after the renderer's
    // read-back (the source is as warm in cache as it is there).
    while (Seconds(start) < seconds || times[0].size() < 5) {
      auto t0 = Clock::now();
      copy = from;  // the reference: the source images copied whole
      times[4].push_back(Seconds(t0));
      for (int k = 0; k < 4; ++k) {
        const bool color_only = k < 2;
        if (color_only) {
          copy.rgba = from.rgba;
        } else {
          copy = from;
        }
        t0 = Clock::now();
        remap.Apply(copy.Raw(source, color_only), &out, k % 2 == 0 ? &pool : nullptr);
        times[k].push_back(Seconds(t0));
      }
    }
    double ms[5];
    for (int k = 0; k < 5; ++k) ms[k] = 1e3 * bench::Median(times[k]);
    std::printf("%-14s %5dx%-4d %7.1f %8.3f %10.3f %10.3f %9.3f %9.3f %7.2fx %9.2fx\n", name,
                source.width, source.height, 1e3 * map_s, ms[4], ms[0], ms[1], ms[2], ms[3],
                ms[2] / ms[4], ms[0] / 1.0);
  }

  // Whole frames, end to end: the sample level from above its lake, as a
  // pinhole (fx = 520) and through each lens; colour alone and all four.
  const scene::Level level =
      scene::LoadLevel(std::string(SANDBOX_SOURCE_DIR) + "/assets/sample/level.toml");
  std::unique_ptr<render::Renderer> renderer = render::MakeRenderer();
  renderer->SetLevel(level, {});
  std::printf("\n%-24s %12s %12s %12s %10s %10s\n", "frame 640x480, sample", "pinhole ms",
              "brown ms", "fisheye ms", "brown/pin", "fish/pin");
  const render::ImageKinds all = render::kColorImage | render::kDepthImage |
                                 render::kSegmentationImage | render::kNormalsImage;
  for (const render::ImageKinds kinds : {render::ImageKinds(render::kColorImage), all}) {
    render::CameraView views[3];
    for (render::CameraView& v : views) {
      v = view;
      v.X_WC =
          Eigen::Translation3d(-40, -30, 25) * Eigen::AngleAxisd(0.6, Eigen::Vector3d::UnitZ());
      v.fov_y_rad = 2.0 * std::atan(240.0 / 520.0);
    }
    views[1].lens = brown, views[2].lens = fisheye;
    render::RenderSettings settings;
    settings.images = kinds;
    render::Frame frame;
    std::vector<double> times[3];
    for (int k = 0; k < 3; ++k) renderer->Render(views[k], {}, {}, settings, &frame);  // warm
    const auto start = Clock::now();
    while (Seconds(start) < 2.0 * seconds || times[0].size() < 5) {
      for (int k = 0; k < 3; ++k) {
        const auto t0 = Clock::now();
        renderer->Render(views[k], {}, {}, settings, &frame);
        times[k].push_back(Seconds(t0));
      }
    }
    double ms[3];
    for (int k = 0; k < 3; ++k) ms[k] = 1e3 * bench::Median(times[k]);
    std::printf("%-24s %12.1f %12.1f %12.1f %9.2fx %9.2fx\n",
                kinds == render::kColorImage ? "colour" : "colour,depth,seg,normal", ms[0], ms[1],
                ms[2], ms[1] / ms[0], ms[2] / ms[0]);
  }
  return 0;
}
