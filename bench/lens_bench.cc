// A lens remap's cost (sensors/render/lens.h): a 640 x 480 frame with colour,
// depth, segmentation and normals gathered through a Brown-Conrady and a
// fisheye lens from their pinhole source frames (twice the lens's density),
// against the budget of 1 ms, beside a plain copy of the source
// images (the reference, in the same process); and the map's one-off build.
// Medians of runs in turns. The source's own render is not counted.
//
//   bench_lens [--seconds S]   (time per figure, default 1)

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "bench/bench_levels.h"
#include "sensors/render/lens.h"

namespace {

using namespace sandbox;
using Clock = std::chrono::steady_clock;

render::Frame SourceFrame(const render::CameraView& source) {
  render::Frame frame;
  frame.width = source.width, frame.height = source.height;
  frame.kinds = render::kColorImage | render::kDepthImage | render::kSegmentationImage |
                render::kNormalsImage;
  const std::size_t n = std::size_t(source.width) * std::size_t(source.height);
  frame.rgb.resize(3 * n), frame.depth_m.resize(n), frame.segment.resize(n);
  frame.normal_C.resize(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    frame.rgb[3 * i] = std::uint8_t(i), frame.rgb[3 * i + 1] = std::uint8_t(i >> 3);
    frame.rgb[3 * i + 2] = std::uint8_t(i >> 6);
    frame.depth_m[i] = float(i % 1000), frame.segment[i] = std::uint32_t(i % 7);
    frame.normal_C[3 * i + 2] = 1.0f;
  }
  return frame;
}

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
  std::printf("%-16s %12s %10s %10s %10s %10s\n", "lens, 640x480", "source px", "map ms", "copy ms",
              "remap ms", "of 1 ms");
  for (const auto& [name, lens] : {std::pair{"brown_conrady", brown}, {"fisheye", fisheye}}) {
    const render::CameraView source = render::SourceView(view, lens);
    const auto built = Clock::now();
    const render::LensRemap remap(lens, view.width, view.height, source);
    const double map_s = Seconds(built);
    const render::Frame from = SourceFrame(source);
    render::Frame out, copy;
    std::vector<double> remaps, copies;
    const auto start = Clock::now();
    while (Seconds(start) < seconds || remaps.size() < 5) {
      auto t0 = Clock::now();
      remap.Apply(from, &out);
      remaps.push_back(Seconds(t0));
      t0 = Clock::now();
      copy = from;  // the reference: the source images copied whole
      copies.push_back(Seconds(t0));
    }
    const double remap_ms = 1e3 * bench::Median(remaps);
    std::printf("%-16s %5dx%-6d %10.2f %10.3f %10.3f %9.3fx\n", name, source.width, source.height,
                1e3 * map_s, 1e3 * bench::Median(copies), remap_ms, remap_ms / 1.0);
  }
  return 0;
}
