// Renders a fixed set of frames and writes each image's raw bytes, for
// scripts/compare-renders to compare two builds byte for byte: the sample
// level (chunks, movable actors, water, textures, the skinned wing) and the
// highlands (streamed terrain tiles, the horizon), each look (plain, fast,
// high; deferred and forward; multisampled; with an overlay) with colour,
// depth, segmentation and normals, and a short flight (levels of detail,
// the shadow maps' reuse). Uses only the Renderer interface (renderer.h).
//
//   render_frames SOURCE_DIR OUT_DIR
// SOURCE_DIR: the tree whose generated assets are drawn (both builds draw the
// same files). Writes OUT_DIR/<case>.<rgb|depth|segment|normal>.

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "scene/level.h"
#include "scene/robot_state.h"
#include "scene/terrain_streamer.h"
#include "sensors/render/cameras.h"
#include "sensors/render/renderer.h"

namespace {

using namespace sandbox;
namespace fs = std::filesystem;

template <typename T>
void Write(const fs::path& path, const std::vector<T>& values) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(values.data()),
            std::streamsize(values.size() * sizeof(T)));
  if (!out) throw std::runtime_error("render_frames: cannot write " + path.string());
}

void WriteFrame(const fs::path& dir, const std::string& name, const render::Frame& frame) {
  if (!frame.rgb.empty()) Write(dir / (name + ".rgb"), frame.rgb);
  if (!frame.depth_m.empty()) Write(dir / (name + ".depth"), frame.depth_m);
  if (!frame.segment.empty()) Write(dir / (name + ".segment"), frame.segment);
  if (!frame.normal_C.empty()) Write(dir / (name + ".normal"), frame.normal_C);
}

struct Case {
  std::string name;
  render::RenderSettings settings;
  bool overlay{false};
};

std::vector<Case> Cases() {
  using render::Quality;
  const render::ImageKinds all(render::kColorImage | render::kDepthImage |
                               render::kSegmentationImage | render::kNormalsImage);
  std::vector<Case> cases;
  for (const auto& [name, quality] :
       {std::pair{"plain", Quality::kPlain}, std::pair{"fast", Quality::kFast},
        std::pair{"high", Quality::kHigh}}) {
    render::RenderSettings settings = render::RenderSettings::Preset(quality);
    settings.images = render::kColorImage;  // levels of detail: colour alone
    cases.push_back({std::string(name) + "-color", settings});
    settings.images = all;
    cases.push_back({std::string(name) + "-all", settings});
    settings.deferred = false;
    cases.push_back({std::string(name) + "-forward-all", settings});
  }
  render::RenderSettings msaa = render::RenderSettings::Preset(Quality::kHigh);
  msaa.msaa_samples = 4;
  msaa.images = all;
  cases.push_back({"high-msaa-all", msaa});
  render::RenderSettings marked = render::RenderSettings::Preset(Quality::kHigh);
  cases.push_back({"high-overlay", marked, true});
  marked.deferred = false;
  cases.push_back({"high-forward-overlay", marked, true});
  render::RenderSettings every_face = render::RenderSettings::Preset(Quality::kFast);
  every_face.cull_hidden_back_faces = false;
  every_face.images = all;
  cases.push_back({"fast-every-face-all", every_face});
  return cases;
}

// Every case, then a flight of a few frames in the high look (colour alone).
void RenderLevel(const std::string& level_name, const scene::Level& level,
                 std::shared_ptr<const scene::TileList> tiles, const Eigen::Isometry3d& X_WB,
                 const fs::path& out) {
  scene::RobotState wing(level.robots.at(0));
  wing.SetPose(X_WB);
  wing.Update();
  render::CameraView view;
  view.width = 320;
  view.height = 240;
  render::ChaseCamera chase({});
  view.X_WC = chase.Update(wing.pose(), 0.0);
  render::Overlay overlay;
  overlay.AddPoint(wing.pose().translation(), {1.f, 0.f, 0.f});
  overlay.AddLine(wing.pose().translation(), wing.pose().translation() + Eigen::Vector3d(0, 0, -20),
                  {0.f, 1.f, 0.f});
  render::Frame frame;
  for (const Case& c : Cases()) {
    // A renderer each: what one draws does not depend on what another drew.
    const std::unique_ptr<render::Renderer> renderer = render::MakeRenderer();
    renderer->SetLevel(level, {});
    renderer->SetTerrain(tiles);
    renderer->Render(view, {}, {&wing}, c.settings, &frame, c.overlay ? &overlay : nullptr);
    WriteFrame(out, level_name + "-" + c.name, frame);
  }
  const std::unique_ptr<render::Renderer> renderer = render::MakeRenderer();
  renderer->SetLevel(level, {});
  renderer->SetTerrain(tiles);
  render::RenderSettings high = render::RenderSettings::Preset(render::Quality::kHigh);
  high.images = render::kColorImage;
  for (int k = 0; k < 6; ++k) {
    wing.SetPose(Eigen::Translation3d(8.0, 3.0, 1.0) * wing.pose());
    wing.Update();
    view.X_WC = chase.Update(wing.pose(), 1.0 / 30.0);
    renderer->Render(view, {}, {&wing}, high, &frame);
    WriteFrame(out, level_name + "-flight" + std::to_string(k), frame);
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: render_frames SOURCE_DIR OUT_DIR\n");
    return 2;
  }
  try {
    const fs::path source(argv[1]), out(argv[2]);
    fs::create_directories(out);
    const scene::Level sample = scene::LoadLevel((source / "assets/sample/level.toml").string());
    RenderLevel(
        "sample", sample, nullptr,
        Eigen::Translation3d(-40, -30, 25) * Eigen::AngleAxisd(0.6, Eigen::Vector3d::UnitZ()), out);
    const scene::Level highlands =
        scene::LoadLevel((source / "assets/highlands/level.toml").string());
    const Eigen::Isometry3d X_WB(Eigen::Translation3d(2000, 500, 900) *
                                 Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()));
    scene::TerrainStreamer streamer(highlands);
    streamer.Update({X_WB.translation()}, 0.0, nullptr, scene::TerrainStreamer::Wait::kAll);
    RenderLevel("highlands", highlands, streamer.drawn(), X_WB, out);
    std::printf("render_frames: %zu files in %s\n",
                std::size_t(std::distance(fs::directory_iterator(out), fs::directory_iterator())),
                out.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "render_frames: %s\n", e.what());
    return 1;
  }
  return 0;
}
