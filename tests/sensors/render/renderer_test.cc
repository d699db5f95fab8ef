// Over 600 lines: the renderer's image tests, each on its own scene; split by
// subject when it grows again.
// The OSMesa renderer and the cameras: colours, depth against the ray caster,
// textures (a generated quad, CesiumMan's embedded texture), the bent wing's silhouette, the chase
// camera's aim and lag.

#include "sensors/render/renderer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <sstream>
#include <tuple>

#include "app/images.h"
#include "assets/generators/sample_terrain.h"
#include "scene/collision_world.h"
#include "scene/level.h"
#include "sensors/face_scanner.h"
#include "sensors/ray_caster.h"
#include "sensors/render/cameras.h"
#include "sensors/render/debug_overlay.h"
#include "sensors/render/frame_targets.h"
#include "tests/test_util.h"

namespace sandbox::render {
namespace {

using Eigen::Isometry3d;
using Eigen::Vector3d;

std::string Generated(const std::string& file) {
  return std::string(SANDBOX_SOURCE_DIR) + "/assets/sample/generated/" + file;
}

// Pixel (column, row) of world point p seen by `view` (row 0 at the top).
Eigen::Vector2d Project(const CameraView& view, const Vector3d& p_W) {
  const Vector3d p_C = view.X_WC.inverse() * p_W;  // x forward, y left, z up
  const double f = 0.5 * view.height / std::tan(0.5 * view.fov_y_rad);
  return {0.5 * view.width - f * p_C.y() / p_C.x(), 0.5 * view.height - f * p_C.z() / p_C.x()};
}

const std::uint8_t* Pixel(const Frame& frame, int column, int row) {
  return &frame.rgb[3 * (std::size_t(row) * std::size_t(frame.width) + std::size_t(column))];
}

// A level of one actor, `name`, from `file` in `dir`, and a renderer with it.
struct OneActorScene {
  OneActorScene(const testing::TempDir& dir, const std::string& name, const std::string& file)
      : level(scene::LoadLevel(dir.Write(
            "level.toml", "[[actor]]\nname = \"" + name + "\"\nfile = \"" + file + "\"\n"))),
        renderer(MakeRenderer()) {
    renderer->SetLevel(level, app::OpenCvTextureDecoder());
  }
  scene::Level level;
  std::unique_ptr<Renderer> renderer;
};

class RendererTest : public ::testing::Test {
 protected:
  // Casts the level's rays through the centres of every `row_step`-th row from
  // `row0` and `column_step`-th column from `column0`; returns those pixels.
  std::vector<std::pair<int, int>> CastThroughPixels(const CameraView& view, int row0, int row_step,
                                                     int column0, int column_step,
                                                     sensors::RayHits* hits) const {
    const scene::CollisionWorld world(level_);
    sensors::RayCaster caster(1);
    sensors::RayBatch rays;
    rays.origin_W = view.X_WC.translation();
    std::vector<std::pair<int, int>> pixels;
    const double f = 0.5 * view.height / std::tan(0.5 * view.fov_y_rad);
    for (int row = row0; row < view.height; row += row_step) {
      for (int column = column0; column < view.width; column += column_step) {
        // The ray through the pixel centre, in the camera frame (x forward).
        const Vector3d d_C(1.0, -(column + 0.5 - 0.5 * view.width) / f,
                           -(row + 0.5 - 0.5 * view.height) / f);
        rays.start.emplace_back(0.f, 0.f, 0.f);
        rays.direction.push_back((view.X_WC.linear() * d_C.normalized()).cast<float>());
        rays.length_m.push_back(2000.f);
        pixels.emplace_back(column, row);
      }
    }
    caster.Cast(world, rays, {}, hits);
    return pixels;
  }

  // The sample terrain and tower only (no water, no robot): what the rays see is drawn.
  RendererTest()
      : level_(scene::LoadLevel(dir_.Write(
            "level.toml", "[[actor]]\nname = \"terrain\"\nfile = \"" + Generated("terrain.gltf") +
                              "\"\n[[actor]]\nname = \"tower\"\nfile = \"" +
                              Generated("tower.gltf") + "\"\nposition = [-30, 45, 7.76]\n"))),
        renderer_(MakeRenderer()) {
    renderer_->SetLevel(level_, app::OpenCvTextureDecoder());
  }
  testing::TempDir dir_;
  scene::Level level_;
  std::unique_ptr<Renderer> renderer_;
};

TEST_F(RendererTest, SkyAboveTerrainBelow) {
  CameraView view;
  view.X_WC = LookAt(Vector3d(0, -150, 40), Vector3d(0, 0, 40));  // level, looking north
  Frame frame;
  const RenderSettings settings;
  renderer_->Render(view, {}, {}, settings, &frame);
  // The sky's gradient: the haze colour at the horizon, deeper with elevation
  // (renderer.cc: zenith = 0.55 horizon + (0.02, 0.08, 0.25), weight sin(elevation)^0.6);
  // the top row's centre looks up by atan(tan(fov / 2) * (1 - 2.5 / 240)).
  const std::uint8_t* top = Pixel(frame, 320, 2);
  const double elevation = std::atan(std::tan(0.5 * view.fov_y_rad) * (1.0 - 2.5 / 240.0));
  const double w = std::pow(std::sin(elevation), 0.6);
  const Eigen::Vector3d horizon = settings.sky_rgb.cast<double>();
  const Eigen::Vector3d zenith = 0.55 * horizon + Eigen::Vector3d(0.02, 0.08, 0.25);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(top[c], 255 * ((1 - w) * horizon[c] + w * zenith[c]), 1.5) << c;
  }
  EXPECT_LT(top[0], 255 * horizon[0] - 20);  // deeper than the horizon
  const std::uint8_t* bottom = Pixel(frame, 320, 470);
  EXPECT_GT(bottom[1], bottom[0]);  // the terrain's green
  EXPECT_GT(bottom[1], bottom[2]);
  EXPECT_TRUE(std::isinf(frame.depth_m[2 * 640 + 320]));
}

// Views of different sizes in turn (a renderer's cameras, a lens's source)
// each draw into their own kept framebuffers: a frame drawn between frames
// of other sizes, past the number of sizes kept, is the frame drawn alone.
TEST_F(RendererTest, ViewsOfSeveralSizesInTurnDrawWhatEachDrawsAlone) {
  RenderSettings settings;
  settings.images = kColorImage | kDepthImage | kSegmentationImage | kNormalsImage;
  const auto view_of = [](int width, int height) {
    CameraView view;
    view.X_WC = LookAt(Vector3d(-60, -120, 50), Vector3d(-30, 45, 10));
    view.width = width, view.height = height;
    return view;
  };
  const std::pair<int, int> sizes[] = {{640, 480}, {320, 240}, {200, 100}, {160, 120},
                                       {96, 64},   {640, 480}, {320, 240}, {640, 480}};
  std::map<std::pair<int, int>, Frame> first;
  int compared = 0;
  for (const auto& [width, height] : sizes) {
    Frame frame;
    renderer_->Render(view_of(width, height), {}, {}, settings, &frame);
    ASSERT_EQ(frame.width, width);
    const auto [kept, added] = first.emplace(std::make_pair(width, height), frame);
    if (added) continue;
    EXPECT_TRUE(frame.rgb == kept->second.rgb) << width << " x " << height;
    EXPECT_TRUE(frame.depth_m == kept->second.depth_m) << width << " x " << height;
    EXPECT_TRUE(frame.segment == kept->second.segment) << width << " x " << height;
    EXPECT_TRUE(frame.normal_C == kept->second.normal_C) << width << " x " << height;
    ++compared;
  }
  EXPECT_EQ(compared, 3);
  EXPECT_GT(FrameTargets::kSizesKept, 1u);
  EXPECT_LT(FrameTargets::kSizesKept, 5u);  // so that 640 x 480 was dropped and made anew
}

TEST_F(RendererTest, DepthAgreesWithTheRayCaster) {
  CameraView view;
  view.X_WC = LookAt(Vector3d(10, -120, 45), Vector3d(-30, 45, 10));  // the tower, the hills
  Frame frame;
  renderer_->Render(view, {}, {}, {}, &frame);
  sensors::RayHits hits;
  const std::vector<std::pair<int, int>> pixels = CastThroughPixels(view, 4, 37, 4, 41, &hits);
  const double f = 0.5 * view.height / std::tan(0.5 * view.fov_y_rad);
  int compared = 0;
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    const auto [column, row] = pixels[i];
    const float depth =
        frame.depth_m[std::size_t(row) * std::size_t(view.width) + std::size_t(column)];
    if (hits.surface[i] == sensors::RayHits::kNoHit) {
      EXPECT_TRUE(std::isinf(depth)) << column << ", " << row;
      continue;
    }
    const Vector3d d_C(1.0, -(column + 0.5 - 0.5 * view.width) / f,
                       -(row + 0.5 - 0.5 * view.height) / f);
    const double expected = hits.distance_m[i] / d_C.norm();  // along the optical axis
    EXPECT_NEAR(depth, expected, 0.02 + 1e-3 * expected) << column << ", " << row;
    ++compared;
  }
  EXPECT_GT(compared, 60);
}

// A full face scan at `at` (2 m samples) of the fixture's level.
sensors::FaceScan FullScan(const scene::Level& level, const Vector3d& at) {
  const scene::CollisionWorld world(level);
  sensors::RayCaster caster(1);
  sensors::FaceScannerConfig config;
  config.resolution_m = 2.0;
  config.refresh = sensors::Refresh::kFull;
  const sensors::FaceScanner scanner(config);
  sensors::FaceScan scan = scanner.EmptyScan();
  scanner.Scan(world, caster, {}, Isometry3d(Eigen::Translation3d(at)), 0, &scan);
  return scan;
}

// Calls visit(i, rgb) for each overlay point i in front of the scene (its
// distance along the optical axis at most the depth `plain` drew there) with
// the colour `marked` shows at its pixel.
template <typename Visit>
void ForEachVisibleSample(const CameraView& view, const Overlay& overlay, const Frame& plain,
                          const Frame& marked, Visit visit) {
  for (std::size_t i = 0; i < overlay.points_W.size(); ++i) {
    const Eigen::Vector2d pixel = Project(view, overlay.points_W[i]);
    const double along = (view.X_WC.inverse() * overlay.points_W[i]).x();
    const int column = int(std::floor(pixel.x())), row = int(std::floor(pixel.y()));
    if (along <= 0 || column < 2 || row < 2 || column >= view.width - 2 || row >= view.height - 2)
      continue;
    const float depth =
        plain.depth_m[std::size_t(row) * std::size_t(view.width) + std::size_t(column)];
    if (along > depth * 1.001 + 0.05) continue;  // behind the terrain: hidden
    visit(i, Pixel(marked, column, row));
  }
}

TEST_F(RendererTest, OverlayMarksEachScannedSampleInItsColourWithoutTouchingDepth) {
  // A full face scan 12 m above the valley floor: the lower face hits the
  // terrain (occupied), the upper faces reach into the sky (free).
  const sensors::FaceScan scan = FullScan(level_, Vector3d(0, 0, 12));
  Overlay overlay;
  AddFaceScan(scan, 0.0, &overlay);
  CameraView view;
  view.X_WC = LookAt(Vector3d(0, -70, 45), Vector3d(0, 0, 5));
  Frame plain, marked;
  renderer_->Render(view, {}, {}, {}, &plain);
  renderer_->Render(view, {}, {}, {}, &marked, &overlay);
  EXPECT_EQ(plain.depth_m, marked.depth_m);
  // Each visible sample shows its own colour at its pixel.
  int checked[2] = {0, 0}, right[2] = {0, 0};
  ForEachVisibleSample(view, overlay, plain, marked, [&](std::size_t i, const std::uint8_t* rgb) {
    const bool occupied = overlay.point_rgb[i].x() > 0.5f;
    const bool red = rgb[0] > 200 && rgb[1]<80, green = rgb[1]> 180 && rgb[0] < 80;
    ++checked[occupied];
    right[occupied] += occupied ? red : green;
  });
  EXPECT_GT(checked[0], 500);
  EXPECT_GT(checked[1], 200);
  EXPECT_GT(right[0], 0.95 * checked[0])
      << right[0] << " of " << checked[0] << " free samples green";
  EXPECT_GT(right[1], 0.95 * checked[1])
      << right[1] << " of " << checked[1] << " occupied samples red";
}

// Coloured by surface id, each visible occupied sample shows its id's colour
// (SurfaceColour) and the free ones grey; samples on two surfaces differ.
TEST_F(RendererTest, OverlayByIdShowsEachSampleInItsSurfaceColour) {
  // Beside the tower: the scan meets the terrain and the tower.
  const Vector3d at(-20, 35, 14);
  const sensors::FaceScan scan = FullScan(level_, at);
  Overlay overlay;
  AddFaceScan(scan, 0.0, &overlay, SampleColour::kSurface);
  std::set<std::int32_t> ids;
  for (const sensors::ScanFace& face : scan.faces)
    ids.insert(face.surface.begin(), face.surface.end());
  ids.erase(0);
  ASSERT_EQ(ids.size(), 2u);  // actors 0 and 1: ids 1 and 2
  std::set<std::tuple<float, float, float>> colours;
  for (const std::int32_t id : ids) {
    const Eigen::Vector3f c = SurfaceColour(id);
    colours.insert({c.x(), c.y(), c.z()});
  }
  EXPECT_EQ(colours.size(), ids.size());
  // The samples' colours: those of the ids the scan met, and grey (free).
  std::set<std::tuple<float, float, float>> drawn;
  for (const Eigen::Vector3f& c : overlay.point_rgb) drawn.insert({c.x(), c.y(), c.z()});
  colours.insert({0.5f, 0.5f, 0.5f});
  EXPECT_EQ(drawn, colours);
  CameraView view;
  view.X_WC = LookAt(at + Vector3d(0, -70, 33), at + Vector3d(0, 0, -7));
  Frame plain, marked;
  renderer_->Render(view, {}, {}, {}, &plain);
  renderer_->Render(view, {}, {}, {}, &marked, &overlay);
  int checked = 0, right = 0;
  ForEachVisibleSample(view, overlay, plain, marked, [&](std::size_t i, const std::uint8_t* rgb) {
    bool near = true;
    for (int k = 0; k < 3; ++k) near &= std::abs(rgb[k] - 255.f * overlay.point_rgb[i][k]) < 40.f;
    ++checked;
    right += near;
  });
  EXPECT_GT(checked, 500);
  EXPECT_GT(right, 0.95 * checked) << right << " of " << checked << " samples in their colour";
}

TEST(DebugOverlayTest, ActorBoundsFollowTheActorAndStubsPointBackAlongTheRay) {
  scene::Level level;
  scene::Actor crate;
  crate.movable = true;
  crate.bounds_W = Eigen::AlignedBox3d(Vector3d(-1, -2, 0), Vector3d(1, 2, 3));
  level.actors.push_back(crate);
  Overlay overlay;
  // Moved 10 m east and turned 90 degrees about z: x spans -2..2 around 10, y -1..1.
  Isometry3d X_WA = Eigen::Translation3d(10, 0, 0) * Eigen::AngleAxisd(M_PI / 2, Vector3d::UnitZ());
  AddActorBounds(level, {X_WA}, false, &overlay);
  ASSERT_EQ(overlay.line_rgb.size(), 12u);
  Eigen::AlignedBox3d box;
  for (const Vector3d& p : overlay.lines_W) box.extend(p);
  EXPECT_TRUE(box.min().isApprox(Vector3d(8, -1, 0), 1e-9)) << box.min().transpose();
  EXPECT_TRUE(box.max().isApprox(Vector3d(12, 1, 3), 1e-9)) << box.max().transpose();
  for (std::size_t i = 0; i < overlay.lines_W.size();
       i += 2) {  // each edge along one axis, full length
    const Vector3d edge = (overlay.lines_W[i + 1] - overlay.lines_W[i]).cwiseAbs();
    EXPECT_EQ((edge.array() > 1e-9).count(), 1);
  }
  // A static actor is skipped unless asked for.
  level.actors[0].movable = false;
  Overlay none, all;
  AddActorBounds(level, {}, false, &none);
  AddActorBounds(level, {}, true, &all);
  EXPECT_TRUE(none.empty());
  EXPECT_EQ(all.line_rgb.size(), 12u);

  // Stubs: 0.5 m from the sample back towards the sensor.
  sensors::FaceScan scan;
  scan.n = 1;
  scan.faces[0].tick = 3;
  scan.faces[0].X_WS = Isometry3d(Eigen::Translation3d(1, 2, 3));
  scan.faces[0].X_WB = scan.faces[0].X_WS;
  scan.half_extent_m = 0.0;  // one sample, on the box's +X axis: (11, 2, 3)
  scan.faces[0].occupancy = {sensors::kOccupied};
  scan.faces[0].distance_m = {10.0f};
  Overlay stubs;
  AddFaceScan(scan, 0.5, &stubs);
  ASSERT_EQ(stubs.lines_W.size(), 2u);
  EXPECT_TRUE(stubs.lines_W[1].isApprox(Vector3d(10.5, 2, 3)));
  EXPECT_TRUE(stubs.points_W.empty());
}

TEST_F(RendererTest, SegmentIdsMatchTheActorsTheRaysHit) {
  CameraView view;
  view.X_WC = LookAt(Vector3d(10, -120, 45), Vector3d(-30, 45, 10));  // the tower, the hills
  RenderSettings settings;
  settings.images = kSegmentationImage;
  Frame frame;
  renderer_->Render(view, {}, {}, settings, &frame);
  ASSERT_EQ(frame.segment.size(), std::size_t(view.width * view.height));
  EXPECT_TRUE(frame.rgb.empty());
  sensors::RayHits hits;
  const std::vector<std::pair<int, int>> pixels = CastThroughPixels(view, 1, 6, 2, 7, &hits);
  int same = 0, tower = 0;
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    const auto [column, row] = pixels[i];
    const std::uint32_t id =
        frame.segment[std::size_t(row) * std::size_t(view.width) + std::size_t(column)];
    const auto expected = std::uint32_t(hits.surface[i]);  // one vocabulary
    same += id == expected;
    tower += expected == 2u;
  }
  EXPECT_GT(tower, 40);  // the tower is in view
  EXPECT_GT(same, 0.99 * double(pixels.size())) << same << " of " << pixels.size();
}

TEST(RendererLookTest, NormalsOfATiltedPlaneInTheCameraFrame) {
  // A square tilted 30 degrees about the world y axis: its normal (sin 30, 0, cos 30).
  testing::TempDir dir;
  const double s = std::sin(M_PI / 6), c = std::cos(M_PI / 6);
  std::ostringstream obj;
  obj << "o plane\n";
  for (const auto& [u, v] : {std::pair{-5, -5}, {5, -5}, {5, 5}, {-5, 5}}) {
    // (u, v) in the plane spanned by (cos 30, 0, -sin 30) and (0, 1, 0).
    obj << "v " << u * c << " " << v << " " << -u * s << "\n";
  }
  obj << "f 1 2 3 4\n";
  dir.Write("plane.obj", obj.str());
  const OneActorScene scene(dir, "plane", "plane.obj");
  Renderer* renderer = scene.renderer.get();
  CameraView view;
  view.X_WC = LookAt(Vector3d(6, -4, 9), Vector3d::Zero());
  RenderSettings settings;
  settings.images = kNormalsImage | kColorImage;
  Frame frame;
  renderer->Render(view, {}, {}, settings, &frame);
  ASSERT_EQ(frame.normal_C.size(), std::size_t(3 * view.width * view.height));
  const Vector3d n_W(s, 0, c);
  const Vector3d n_C = view.X_WC.linear().transpose() * n_W;  // x forward, y left, z up
  const float* n = &frame.normal_C[3 * (std::size_t(240) * 640 + 320)];
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(n[k], n_C[k], 1e-3) << k;
  const float* sky = &frame.normal_C[0];
  EXPECT_EQ(sky[0] * sky[0] + sky[1] * sky[1] + sky[2] * sky[2], 0.f);
}

// Levels of detail: a finely cut sphere (16k triangles) far away, in a frame
// of colour alone, may be drawn simplified by up to a pixel: its outline stays
// within a pixel of the circle it projects to; with a depth image it is drawn
// as given (and its depth is the sphere's).
TEST(RendererLookTest, ASimplifiedSphereKeepsItsOutlineWithinAPixel) {
  testing::TempDir dir;
  constexpr double kRadius = 5.0, kDistance = 120.0;
  constexpr int kAround = 128, kUp = 64;
  std::ostringstream obj;
  obj << "o sphere\n";
  for (int j = 0; j <= kUp; ++j) {
    for (int i = 0; i < kAround; ++i) {
      const double theta = M_PI * j / kUp, phi = 2.0 * M_PI * i / kAround;
      const Vector3d n(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                       std::cos(theta));
      obj << "v " << kRadius * n.x() << " " << kRadius * n.y() << " " << kRadius * n.z() << "\n"
          << "vn " << n.x() << " " << n.y() << " " << n.z() << "\n";
    }
  }
  for (int j = 0; j < kUp; ++j) {
    for (int i = 0; i < kAround; ++i) {
      const int a = 1 + j * kAround + i, b = 1 + j * kAround + (i + 1) % kAround;
      const int c = a + kAround, d = b + kAround;
      obj << "f " << a << "//" << a << " " << c << "//" << c << " " << d << "//" << d << "\n"
          << "f " << a << "//" << a << " " << d << "//" << d << " " << b << "//" << b << "\n";
    }
  }
  dir.Write("sphere.obj", obj.str());
  const OneActorScene scene(dir, "sphere", "sphere.obj");
  CameraView view;
  view.X_WC = LookAt(Vector3d(-kDistance, 0, 0), Vector3d::Zero());
  RenderSettings settings = RenderSettings::Preset(Quality::kFast);
  settings.haze = false;
  const double f = 0.5 * view.height / std::tan(0.5 * view.fov_y_rad);
  const double r_px = f * kRadius / std::sqrt(kDistance * kDistance - kRadius * kRadius);
  auto sphere_pixels = [&](const Frame& frame) {
    int count = 0;
    for (int row = 0; row < frame.height; ++row) {
      for (int column = 0; column < frame.width; ++column) {
        const std::uint8_t* rgb = Pixel(frame, column, row);
        count += rgb[2] < rgb[0] + 30;  // grey, not the blue sky
      }
    }
    return count;
  };
  Frame simplified, exact;
  settings.images = kColorImage;
  scene.renderer->Render(view, {}, {}, settings, &simplified);
  settings.images = kColorImage | kDepthImage;
  scene.renderer->Render(view, {}, {}, settings, &exact);
  const double disc = M_PI * r_px * r_px;  // 1,294 px
  EXPECT_NEAR(sphere_pixels(exact), disc, M_PI * r_px) << "r = " << r_px << " px";
  EXPECT_NEAR(sphere_pixels(simplified), disc, 2.0 * M_PI * r_px + 4.0);
  EXPECT_NEAR(exact.depth_m[std::size_t(240 * 640 + 320)], kDistance - kRadius, 0.01);
  int differing = 0;
  for (std::size_t i = 0; i < exact.rgb.size(); ++i) {
    differing += std::abs(int(exact.rgb[i]) - int(simplified.rgb[i])) > 8;
  }
  EXPECT_GT(differing, 0) << "the colour frame was drawn simplified";
  settings.images = kColorImage;
  settings.lod_px = 0.f;
  Frame as_given;
  scene.renderer->Render(view, {}, {}, settings, &as_given);
  EXPECT_EQ(as_given.rgb, exact.rgb) << "lod_px = 0: as given";
}

TEST(RendererLookTest, ABoxCastsItsShadowWhereTrigonometryPutsIt) {
  // A 2 m x 2 m x 4 m box on a plane; the sun 45 degrees up in the -x
  // direction: the top edge's shadow ends at x = 1 + 4 / tan 45 = 5.
  testing::TempDir dir;
  dir.Write("ground.obj",
            "o ground\nv -40 -40 0\nv 40 -40 0\nv 40 40 0\nv -40 40 0\nvn 0 0 1\n"
            "f 1//1 2//1 3//1 4//1\n");
  std::ostringstream box;
  box << "o box\n";
  for (int k = 0; k < 8; ++k) {
    box << "v " << (k & 1 ? 1 : -1) << " " << (k & 2 ? 1 : -1) << " " << (k & 4 ? 4 : 0) << "\n";
  }
  box << "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
  dir.Write("box.obj", box.str());
  const scene::Level level =
      scene::LoadLevel(dir.Write("level.toml",
                                 "[[actor]]\nname = \"ground\"\nfile = \"ground.obj\"\n"
                                 "[[actor]]\nname = \"box\"\nfile = \"box.obj\"\n"));
  auto renderer = MakeRenderer();
  renderer->SetLevel(level, app::OpenCvTextureDecoder());
  CameraView view;
  view.X_WC = LookAt(Vector3d(5, -14, 14), Vector3d(5, 0, 0));
  RenderSettings settings = RenderSettings::Preset(Quality::kHigh);
  settings.sun_direction_W = Eigen::Vector3f(-1.f, 0.f, 1.f);
  settings.haze = false;
  Frame frame;
  renderer->Render(view, {}, {}, settings, &frame);
  // Along the ground's line y = 0 from x = 2 (in shadow) to x = 8 (lit): where
  // the brightness crosses half way, against the projection of x = 5.
  const Eigen::Vector2d a = Project(view, Vector3d(2, 0, 0)), b = Project(view, Vector3d(8, 0, 0));
  auto brightness = [&](const Eigen::Vector2d& p) {
    const std::uint8_t* rgb = Pixel(frame, int(p.x()), int(p.y()));
    return rgb[0] + rgb[1] + rgb[2];
  };
  const double dark = brightness(a), lit = brightness(b);
  ASSERT_GT(lit, dark + 60) << "no shadow";
  const int steps = int((b - a).norm() * 4);
  double edge = -1;
  for (int i = 0; i <= steps; ++i) {
    const Eigen::Vector2d p = a + (b - a) * (double(i) / steps);
    if (brightness(p) > 0.5 * (dark + lit)) {
      edge = (p - a).norm();
      break;
    }
  }
  const double expected = (Project(view, Vector3d(5, 0, 0)) - a).norm();
  EXPECT_NEAR(edge, expected, 2.0);
}

// FXAA on the silhouette of a dark square against the sky. The square's top
// edge, projected, is a line known to a fraction of a pixel; each column's
// coverage (how far its luma lies between sky and square) puts the edge at
// a sub-pixel row. Without antialiasing that row is the pixel centres'
// quantisation (RMS 1 / sqrt(12) = 0.29 px); 4x multisampling and FXAA come
// closer to the line. Where the image is flat FXAA changes nothing.
TEST(RendererLookTest, FxaaPutsEdgesNearerTheirLineAndLeavesFlatAreas) {
  testing::TempDir dir;
  dir.Write("dark.mtl", "newmtl dark\nKd 0.03 0.03 0.03\n");
  dir.Write("square.obj",
            "mtllib dark.mtl\no square\nusemtl dark\nv -5 -5 0\nv 5 -5 0\nv 5 5 0\nv -5 5 0\n"
            "f 1 2 3 4\n");
  const OneActorScene scene(dir, "square", "square.obj");
  Renderer* renderer = scene.renderer.get();
  CameraView view;
  // From below and to the side: the square's top edge crosses the sky at about 25 degrees.
  view.X_WC = LookAt(Vector3d(3, -12, -6), Vector3d(0.5, 0.3, 0)) *
              Eigen::AngleAxisd(0.3, Vector3d::UnitX());
  RenderSettings none = RenderSettings::Preset(Quality::kFast);
  none.haze = false;
  none.images = kColorImage;
  RenderSettings fxaa = none, msaa = none;
  fxaa.fxaa = true;
  msaa.msaa_samples = 4;
  Frame none_frame, fxaa_frame, msaa_frame;
  renderer->Render(view, {}, {}, none, &none_frame);
  renderer->Render(view, {}, {}, fxaa, &fxaa_frame);
  renderer->Render(view, {}, {}, msaa, &msaa_frame);
  auto luma = [](const Frame& frame, int x, int y) {
    const std::uint8_t* p = Pixel(frame, x, y);
    return 0.299 * p[0] + 0.587 * p[1] + 0.114 * p[2];
  };
  // The top edge: from the leftmost projected corner to the topmost.
  std::vector<Eigen::Vector2d> corners;
  for (const auto& [x, y] : {std::pair{-5, -5}, {5, -5}, {5, 5}, {-5, 5}}) {
    corners.push_back(Project(view, Vector3d(x, y, 0)));
  }
  const auto by_x = [](const auto& p, const auto& q) { return p.x() < q.x(); };
  const auto by_y = [](const auto& p, const auto& q) { return p.y() < q.y(); };
  const Eigen::Vector2d left = *std::min_element(corners.begin(), corners.end(), by_x);
  const Eigen::Vector2d top = *std::min_element(corners.begin(), corners.end(), by_y);
  ASSERT_GT(top.x() - left.x(), 200.0);
  auto rms_error = [&](const Frame& frame) {
    double sum = 0.0;
    int n = 0;
    for (int x = int(left.x()) + 20; x < int(top.x()) - 20; ++x) {
      const double true_y =
          left.y() + (x + 0.5 - left.x()) * (top.y() - left.y()) / (top.x() - left.x());
      const int r0 = int(true_y);
      const double sky = luma(frame, x, r0 - 4), dark = luma(frame, x, r0 + 5);
      double sky_rows = 0.0;
      for (int r = r0 - 3; r <= r0 + 4; ++r) {
        sky_rows += std::clamp((luma(frame, x, r) - dark) / (sky - dark), 0.0, 1.0);
      }
      const double y = r0 - 3 + sky_rows;
      sum += (y - true_y) * (y - true_y);
      ++n;
    }
    return std::sqrt(sum / n);
  };
  const double error_none = rms_error(none_frame), error_fxaa = rms_error(fxaa_frame),
               error_msaa = rms_error(msaa_frame);
  EXPECT_NEAR(error_none, 1.0 / std::sqrt(12.0), 0.08);  // the measure holds without AA
  EXPECT_LT(error_msaa, 0.7 * error_none);               // and sees what multisampling does
  EXPECT_LT(error_fxaa, 0.8 * error_none)
      << "RMS px: none " << error_none << ", FXAA " << error_fxaa << ", MSAA " << error_msaa;
  int flat_pixels = 0, flat_changed = 0;
  for (int y = 2; y < view.height - 2; ++y) {
    for (int x = 2; x < view.width - 2; ++x) {
      double lo = 255.0, hi = 0.0;
      for (int dy = -2; dy <= 2; ++dy) {
        for (int dx = -2; dx <= 2; ++dx) {
          lo = std::min(lo, luma(none_frame, x + dx, y + dy));
          hi = std::max(hi, luma(none_frame, x + dx, y + dy));
        }
      }
      if (hi - lo <= 2.0) {
        ++flat_pixels;
        flat_changed += std::memcmp(Pixel(none_frame, x, y), Pixel(fxaa_frame, x, y), 3) != 0;
      }
    }
  }
  ASSERT_GT(flat_pixels, 100000);
  EXPECT_EQ(flat_changed, 0);
}

// The shadow maps keep what never moves between frames and redraw what
// moves: a renderer that drew other views and other placements before gives
// the image a new renderer gives, as the camera moves a little (the kept map
// stays) and far (it is redrawn) and a movable box moves under the sun.
// (The new renderer's context is made after the kept one's: the kept one
// makes its own current again.)
TEST(RendererLookTest, KeptShadowMapsGiveWhatFreshOnesGive) {
  testing::TempDir dir;
  dir.Write("ground.obj",
            "o ground\nv -60 -60 0\nv 60 -60 0\nv 60 60 0\nv -60 60 0\nvn 0 0 1\n"
            "f 1//1 2//1 3//1 4//1\n");
  auto block = [](double half, double height) {
    std::ostringstream obj;
    obj << "o block\n";
    for (int k = 0; k < 8; ++k) {
      obj << "v " << (k & 1 ? half : -half) << " " << (k & 2 ? half : -half) << " "
          << (k & 4 ? height : 0.0) << "\n";
    }
    obj << "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
    return obj.str();
  };
  dir.Write("pole.obj", block(0.5, 8.0));
  dir.Write("box.obj", block(1.0, 3.0));
  const scene::Level level = scene::LoadLevel(
      dir.Write("level.toml",
                "[[actor]]\nname = \"ground\"\nfile = \"ground.obj\"\n"
                "[[actor]]\nname = \"pole\"\nfile = \"pole.obj\"\nposition = [-6, 4, 0]\n"
                "[[actor]]\nname = \"box\"\nfile = \"box.obj\"\nmovable = true\n"));
  const int box = level.FindActor("box");
  ASSERT_GE(box, 0);
  RenderSettings settings = RenderSettings::Preset(Quality::kHigh);
  settings.haze = false;
  settings.images = kColorImage;
  settings.sun_direction_W = Eigen::Vector3f(1.f, -0.3f, 1.2f);  // shadows fall towards -x
  auto kept = MakeRenderer();
  kept->SetLevel(level, app::OpenCvTextureDecoder());
  struct Step {
    Vector3d eye, box_at;
  };
  int frames_with_shadows = 0;
  for (const Step& step : {Step{{4, -20, 12}, {0, 0, 0}}, Step{{4.3, -20.2, 12}, {3, -2, 0}},
                           Step{{-25, -5, 15}, {-2, 3, 0}}, Step{{-25.2, -5, 15.1}, {0, 0, 0}}}) {
    CameraView view;
    view.X_WC = LookAt(step.eye, Vector3d(0, 0, 0));
    std::vector<Isometry3d> poses;
    for (const scene::Actor& actor : level.actors) poses.push_back(actor.X_WA);
    poses[std::size_t(box)] = Isometry3d(Eigen::Translation3d(step.box_at));
    Frame from_kept, from_fresh;
    kept->Render(view, poses, {}, settings, &from_kept);
    auto fresh = MakeRenderer();
    fresh->SetLevel(level, app::OpenCvTextureDecoder());
    fresh->Render(view, poses, {}, settings, &from_fresh);
    int differing = 0;
    for (std::size_t i = 0; i < from_kept.rgb.size(); ++i) {
      differing += std::abs(int(from_kept.rgb[i]) - int(from_fresh.rgb[i])) > 2;
    }
    EXPECT_LE(differing, 20) << "camera at " << step.eye.transpose();
    // The box's shadow is there: the ground beside it, away from the sun, darker than the open.
    const Eigen::Vector2d p = Project(view, step.box_at + Vector3d(-1.6, 0.3, 0.0)),
                          q = Project(view, Vector3d(10, -10, 0));
    frames_with_shadows += Pixel(from_kept, int(p.x()), int(p.y()))[1] + 30 <
                           Pixel(from_kept, int(q.x()), int(q.y()))[1];
  }
  EXPECT_EQ(frames_with_shadows, 4);
}

TEST(RendererTextureTest, TextureColoursShow) {
  // A square with a two-colour texture: red on the left half, blue on the right.
  testing::TempDir dir;
  cv::Mat texture(8, 16, CV_8UC3, cv::Scalar(255, 0, 0));      // BGR blue
  texture(cv::Rect(0, 0, 8, 8)).setTo(cv::Scalar(0, 0, 255));  // left half red
  ASSERT_TRUE(cv::imwrite((dir.path() / "check.png").string(), texture));
  dir.Write("square.mtl", "newmtl check\nKd 1 1 1\nmap_Kd check.png\n");
  dir.Write("square.obj",
            "mtllib square.mtl\no square\nv 0 -1 -1\nv 0 1 -1\nv 0 1 1\nv 0 -1 1\n"
            "vt 1 0\nvt 0 0\nvt 0 1\nvt 1 1\nusemtl check\nf 1/1 2/2 3/3 4/4\n");
  const OneActorScene scene(dir, "square", "square.obj");
  Renderer* renderer = scene.renderer.get();
  EXPECT_TRUE(renderer->warnings().empty());
  CameraView view;
  view.X_WC = LookAt(Vector3d(-5, 0, 0), Vector3d::Zero());  // facing the square's -x side
  Frame frame;
  renderer->Render(view, {}, {}, {}, &frame);
  // Seen from -x the square's +y edge (u = 0, the red half) is on the image's left.
  const Eigen::Vector2d left = Project(view, Vector3d(0, 0.5, 0)),
                        right = Project(view, Vector3d(0, -0.5, 0));
  const std::uint8_t* l = Pixel(frame, int(left.x()), int(left.y()));
  const std::uint8_t* r = Pixel(frame, int(right.x()), int(right.y()));
  EXPECT_GT(l[0], 3 * l[2]) << int(l[0]) << " " << int(l[1]) << " " << int(l[2]);
  EXPECT_GT(r[2], 3 * r[0]) << int(r[0]) << " " << int(r[1]) << " " << int(r[2]);
  // A texture that cannot be read: one warning, the base colour.
  dir.Write("square.mtl", "newmtl check\nKd 1 1 1\nmap_Kd missing.png\n");
  const scene::Level missing = scene::LoadLevel(dir.path() / "level.toml");
  auto plain = MakeRenderer();
  plain->SetLevel(missing, app::OpenCvTextureDecoder());
  ASSERT_EQ(plain->warnings().size(), 1u);
  EXPECT_NE(plain->warnings()[0].find("missing.png cannot be read"), std::string::npos);
}

// Chromaticity (r, g) / (r + g + b) on a 0.02 grid, for colours bright enough
// that 8-bit rounding does not move it; -1 for darker ones.
int ChromaBin(int r, int g, int b) {
  const int sum = r + g + b;
  if (sum < 90) return -1;
  return int(50.0 * r / sum) * 64 + int(50.0 * g / sum);
}

TEST(RendererTextureTest, ATexturedQuadRendersItsTexels) {
  // A 2 m square on the ground with a texture of 4 x 4 distinct colours, seen
  // from straight above with the sun overhead and no haze: every look then
  // lights it by exactly 1 (gamma-correct: 0.75 sun + 0.25 sky from above;
  // plain: 0.35 + 0.65 cos 0), so each texel's centre shows the file's colour.
  // Each cell is 8 x 8 texels, so that filtering at its centre mixes only its own colour.
  testing::TempDir dir;
  cv::Mat cells(4, 4, CV_8UC3), texture;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      cells.at<cv::Vec3b>(r, c) = cv::Vec3b(std::uint8_t(30 + 60 * c), std::uint8_t(240 - 50 * r),
                                            std::uint8_t(17 * (r + 4 * c) % 256));
    }
  }
  cv::resize(cells, texture, cv::Size(32, 32), 0, 0, cv::INTER_NEAREST);
  ASSERT_TRUE(cv::imwrite((dir.path() / "cells.png").string(), texture));
  dir.Write("quad.mtl", "newmtl cells\nKd 1 1 1\nmap_Kd cells.png\n");
  dir.Write("quad.obj",
            "mtllib quad.mtl\no quad\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvn 0 0 1\n"
            "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl cells\nf 1/1/1 2/2/1 3/3/1 4/4/1\n");
  const OneActorScene scene(dir, "quad", "quad.obj");
  Renderer* renderer = scene.renderer.get();
  ASSERT_TRUE(renderer->warnings().empty());
  CameraView view;
  Eigen::Matrix3d R_WC;  // looking down: x forward = -z, y left = +y, z up = +x
  R_WC.col(0) = -Vector3d::UnitZ();
  R_WC.col(1) = Vector3d::UnitY();
  R_WC.col(2) = Vector3d::UnitX();
  view.X_WC.linear() = R_WC;
  view.X_WC.translation() = Vector3d(0, 0, 3);
  for (const Quality quality : {Quality::kPlain, Quality::kFast, Quality::kHigh}) {
    RenderSettings settings = RenderSettings::Preset(quality);
    settings.haze = false;
    settings.sun_direction_W = Eigen::Vector3f(0, 0, 1);
    Frame frame;
    renderer->Render(view, {}, {}, settings, &frame);
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) {
        // Row 0 of the image is its top, v = 1 (OBJ texture coordinates point up).
        const double u = (c + 0.5) / 4, v = 1.0 - (r + 0.5) / 4;
        const Eigen::Vector2d px = Project(view, Vector3d(-1 + 2 * u, -1 + 2 * v, 0));
        const std::uint8_t* got = Pixel(frame, int(px.x()), int(px.y()));
        const cv::Vec3b bgr = cells.at<cv::Vec3b>(r, c);
        for (int k = 0; k < 3; ++k) {
          EXPECT_NEAR(int(got[k]), int(bgr[2 - k]), 2)
              << "quality " << int(quality) << ", texel (" << r << ", " << c << "), channel " << k;
        }
      }
    }
  }
}

TEST(RendererTextureTest, CesiumManShowsItsEmbeddedTextureColours) {
  const std::string file = std::string(SANDBOX_SHARED_ASSETS) + "/cesium-man/CesiumMan.glb";
  if (!std::ifstream(file).good()) GTEST_SKIP() << "no " << file << " (shared assets absent)";
  testing::TempDir dir;
  const scene::Level level = scene::LoadLevel(
      dir.Write("level.toml", "[[actor]]\nname = \"man\"\nfile = \"" + file + "\"\n"));
  ASSERT_EQ(level.textures.size(), 1u);
  // The texture's own colours, decoded here from the file's bytes.
  const scene::EmbeddedTexture& embedded = level.textures[0];
  const cv::Mat texels = cv::imdecode(embedded.bytes, cv::IMREAD_COLOR);  // BGR
  ASSERT_FALSE(texels.empty());
  std::set<int> texture_bins;
  for (int y = 0; y < texels.rows; ++y) {
    for (int x = 0; x < texels.cols; ++x) {
      const cv::Vec3b t = texels.at<cv::Vec3b>(y, x);
      texture_bins.insert(ChromaBin(t[2], t[1], t[0]));
    }
  }
  // Seen from 4 m in front of its middle, with and without its texture.
  const Vector3d centre = level.bounds_W().center();
  CameraView view;
  view.X_WC = LookAt(centre + Vector3d(0, -4, 0), centre);
  Frame textured, plain;
  auto renderer = MakeRenderer();
  renderer->SetLevel(level, app::OpenCvTextureDecoder());
  EXPECT_TRUE(renderer->warnings().empty());
  renderer->Render(view, {}, {}, {}, &textured);
  auto untextured = MakeRenderer();
  untextured->SetLevel(level, {});
  untextured->Render(view, {}, {}, {}, &plain);
  // Where the man is drawn (not sky), lighting scales a colour but keeps its
  // chromaticity: textured pixels take the texture's, many of them; the plain
  // render has the one base colour.
  auto near_texture = [&](int bin) {
    for (int dr = -1; dr <= 1; ++dr) {
      for (int dg = -1; dg <= 1; ++dg) {
        if (texture_bins.count(bin + 64 * dr + dg)) return true;
      }
    }
    return false;
  };
  int drawn = 0, matching = 0;
  std::set<int> textured_bins, plain_bins;
  for (int row = 0; row < view.height; ++row) {
    for (int column = 0; column < view.width; ++column) {
      const std::uint8_t* t = Pixel(textured, column, row);
      const std::uint8_t* p = Pixel(plain, column, row);
      if (std::isinf(
              textured.depth_m[std::size_t(row) * std::size_t(view.width) + std::size_t(column)])) {
        continue;  // sky
      }
      const int bin = ChromaBin(t[0], t[1], t[2]);
      if (bin < 0) continue;
      ++drawn;
      matching += near_texture(bin);
      textured_bins.insert(bin);
      plain_bins.insert(ChromaBin(p[0], p[1], p[2]));
    }
  }
  ASSERT_GT(drawn, 2000) << "the man is not in view";
  EXPECT_GT(matching, 0.95 * drawn) << matching << " of " << drawn;
  EXPECT_GT(textured_bins.size(), 20u);
  EXPECT_LE(plain_bins.size(), 3u);
}

TEST(RendererTextureTest, Quake3MapShowsItsBakedLightmapColours) {
  const std::string file = std::string(SANDBOX_SHARED_ASSETS) + "/q3-de4th-run1/de4th_run1.pk3";
  if (!std::ifstream(file).good()) GTEST_SKIP() << "no " << file << " (shared assets absent)";
  scene::Level level = scene::LoadLevel(file);
  // The lightmaps' own colours (raw RGBA texels from the file, 2x overbright
  // as Quake 3 applies them), where no channel clips.
  std::set<int> lightmap_bins;
  int lit_materials = 0;
  for (const scene::Material& material : level.materials) {
    if (material.lightmap_texture_embedded < 0) continue;
    ++lit_materials;
    const scene::EmbeddedTexture& lightmap =
        level.textures[std::size_t(material.lightmap_texture_embedded)];
    ASSERT_GT(lightmap.height, 0);  // raw texels
    for (std::size_t i = 0; i + 3 < lightmap.bytes.size(); i += 4) {
      const int r = 2 * lightmap.bytes[i], g = 2 * lightmap.bytes[i + 1],
                b = 2 * lightmap.bytes[i + 2];
      if (std::max({r, g, b}) < 250) lightmap_bins.insert(ChromaBin(r, g, b));
    }
  }
  EXPECT_GT(lit_materials, 30);
  // The jump pad's orange glow, seen from across the room.
  CameraView view;
  view.X_WC = Isometry3d(Eigen::Translation3d(-20, 0, 40)) *
              Eigen::AngleAxisd(10 * M_PI / 180, Vector3d::UnitY());
  Frame baked, plain;
  auto renderer = MakeRenderer();
  renderer->SetLevel(level, app::OpenCvTextureDecoder());
  renderer->Render(view, {}, {}, {}, &baked);
  for (scene::Material& material : level.materials) material.lightmap_texture_embedded = -1;
  auto unlit = MakeRenderer();
  unlit->SetLevel(level, app::OpenCvTextureDecoder());
  unlit->Render(view, {}, {}, {}, &plain);
  // Coloured pixels (a channel 40 above another, none clipped) come from the
  // lightmaps, whose colours they keep; without lightmaps white surfaces
  // under the sun give none.
  int coloured = 0, matching = 0, coloured_plain = 0;
  for (int row = 0; row < view.height; ++row) {
    for (int column = 0; column < view.width; ++column) {
      for (const Frame* frame : {&baked, &plain}) {
        const std::uint8_t* p = Pixel(*frame, column, row);
        const int high = std::max({p[0], p[1], p[2]}), low = std::min({p[0], p[1], p[2]});
        if (high - low < 40 || high >= 250) continue;
        if (frame == &plain) {
          ++coloured_plain;
          continue;
        }
        const int bin = ChromaBin(p[0], p[1], p[2]);
        if (bin < 0) continue;
        ++coloured;
        bool near = false;
        for (int dr = -1; dr <= 1 && !near; ++dr) {
          for (int dg = -1; dg <= 1 && !near; ++dg)
            near = lightmap_bins.count(bin + 64 * dr + dg) > 0;
        }
        matching += near;
      }
    }
  }
  EXPECT_GT(coloured, 2000);
  EXPECT_GT(matching, 0.95 * coloured) << matching << " of " << coloured;
  EXPECT_EQ(coloured_plain, 0);
}

TEST(RendererWingTest, BendingMovesTheSilhouetteToTheAnalyticTip) {
  const scene::Level level = scene::LoadLevel(testing::SampleLevel());
  auto renderer = MakeRenderer();
  renderer->SetLevel(level, {});
  scene::RobotState straight(level.robots[0]), bent(level.robots[0]);
  const double roll = 4.5 * M_PI / 180.0;
  for (int b = 1; b <= 20; ++b) {
    const double values[2] = {b <= 10 ? roll : -roll, 0.0};
    ASSERT_TRUE(bent.SetBone(b, values, 2));
  }
  bent.Update();
  // In front of the wing (spawned at (0, 0, 60)), looking back at it, nothing near behind.
  CameraView view;
  view.X_WC = LookAt(Vector3d(40, 0, 62), Vector3d(0, 0, 58));
  Frame frame_straight, frame_bent;
  renderer->Render(view, {}, {&straight}, {}, &frame_straight);
  renderer->Render(view, {}, {&bent}, {}, &frame_bent);
  // The analytic right tip: ten joints 0.6 then 1.2 m out along -y, each rolled 4.5 degrees.
  Isometry3d X = Isometry3d(Eigen::Translation3d(0, 0, 60));
  for (int k = 1; k <= 10; ++k) {
    X = X * Eigen::Translation3d(0, k == 1 ? -0.6 : -1.2, 0) *
        Eigen::AngleAxisd(roll, Vector3d::UnitX());
  }
  const Vector3d tip = X * Vector3d(-0.15, -0.6, 0.0);  // half an element inside the tip
  const Eigen::Vector2d px = Project(view, tip);
  // Beyond the wing: the sky or the far ground (the wing is 40 m away).
  auto is_sky = [&](const Frame& frame) {
    return frame.depth_m[std::size_t(px.y()) * std::size_t(frame.width) + std::size_t(px.x())] >
           100.f;
  };
  EXPECT_FALSE(is_sky(frame_bent)) << px.transpose();     // the bent tip is drawn there
  EXPECT_TRUE(is_sky(frame_straight)) << px.transpose();  // the straight wing is not
}

// A robot of several meshes (the quadrotor: body and rotors) is drawn whole
// from the first frame that sees it, as it is in the next (its meshes are
// uploaded in that first frame: ASan would catch a pointer kept into the
// list while it grew).
TEST(RendererRobotTest, ARobotOfSeveralMeshesIsDrawnTheSameFromItsFirstFrame) {
  const scene::Level level =
      scene::LoadLevel(std::filesystem::path(SANDBOX_SOURCE_DIR) / "assets/robots/robots.toml");
  const scene::RobotModel* quad = nullptr;
  for (const scene::RobotModel& robot : level.robots) {
    if (robot.name == "QUAD") quad = &robot;
  }
  ASSERT_NE(quad, nullptr);
  ASSERT_GT(quad->meshes.size(), 2u);
  scene::RobotState state(*quad);
  state.SetPose(Isometry3d(Eigen::Translation3d(0, 0, 100)));
  state.Update();
  CameraView view;
  view.width = 160, view.height = 120;
  view.X_WC = LookAt(Vector3d(0.5, 0, 100.6), Vector3d(0, 0, 100));  // 0.8 m from the 0.4 m quad
  RenderSettings settings;
  settings.images = kSegmentationImage;
  auto renderer = MakeRenderer();
  renderer->SetLevel(level, {});
  Frame first, second;
  renderer->Render(view, {}, {&state}, settings, &first);
  renderer->Render(view, {}, {&state}, settings, &second);
  const auto robot_pixels = std::count_if(first.segment.begin(), first.segment.end(),
                                          [](std::uint32_t id) { return id != 0; });
  // Body, arms and rotors: about 1,000 pixels at this distance (the arms 3 pixels wide).
  EXPECT_GT(robot_pixels, 600);
  EXPECT_EQ(first.segment, second.segment);
}

// The sample level with its wing mid-turn, as bench_render's looks show it.
struct SampleWithWing {
  SampleWithWing()
      : level(scene::LoadLevel(testing::SampleLevel())),
        renderer(MakeRenderer()),
        wing(level.robots[0]) {
    renderer->SetLevel(level, {});
    wing.SetPose(Eigen::Translation3d(-40, -30, 25) * Eigen::AngleAxisd(0.6, Vector3d::UnitZ()));
    wing.Update();
  }
  scene::Level level;
  std::unique_ptr<Renderer> renderer;
  scene::RobotState wing;
};

// Deferred shading (the CPU's lighting of the G-buffer) against forward
// shading (llvmpipe's, as the scene programs draw) on the sample level's chase
// view: terrain, lake, tower, wing, their shadows, haze and sky. The two
// implement one look; they differ by rounding, by the detail texture's level
// at silhouettes and by the shadow lookups' levels-of-detail offset.
TEST(RendererLookTest, DeferredShadingMatchesForwardShading) {
  SampleWithWing sample;
  scene::RobotState& wing = sample.wing;
  Renderer* renderer = sample.renderer.get();
  CameraView view;
  view.X_WC = ChaseCamera({}).Update(wing.pose(), 0.0);
  for (const Quality quality : {Quality::kFast, Quality::kHigh}) {
    RenderSettings settings = RenderSettings::Preset(quality);
    settings.images = kColorImage;
    Frame deferred, forward;
    renderer->Render(view, {}, {&wing}, settings, &deferred);
    settings.deferred = false;
    renderer->Render(view, {}, {&wing}, settings, &forward);
    ASSERT_EQ(deferred.rgb.size(), forward.rgb.size());
    double sum = 0.0;
    std::size_t far_off = 0;
    const std::size_t pixels = deferred.rgb.size() / 3;
    for (std::size_t i = 0; i < pixels; ++i) {
      int most = 0;
      for (int c = 0; c < 3; ++c) {
        const int d = std::abs(int(deferred.rgb[3 * i + c]) - int(forward.rgb[3 * i + c]));
        sum += d;
        most = std::max(most, d);
      }
      far_off += most > 8;
    }
    const int q = int(quality);
    EXPECT_LT(sum / (3.0 * double(pixels)), 1.5) << q;
    EXPECT_LT(double(far_off) / double(pixels), 0.005) << q;
  }
}

// Culling the back faces that cannot be seen (hidden_faces.h) changes no
// pixel but a few on silhouettes' edges. The sample level (its terrain a
// height field; rocks, wall, tower, boulder, gate and the wing solids) with
// every back face drawn is the reference: from the chase view, from half a
// metre above the wing (culled, close by), and from where back faces do show
// (each of these fails when culling ignores the eye): under the ground,
// beside the terrain below its edge, 2 cm above the grass (the near plane
// cuts it), inside the boulder and inside the wing.
TEST(RendererLookTest, CullingHiddenBackFacesChangesNoPixel) {
  SampleWithWing sample;
  scene::RobotState& wing = sample.wing;
  Renderer* renderer = sample.renderer.get();
  const double ground = assets::sample::TerrainHeight(60, 20);
  struct Case {
    std::string name;
    Isometry3d X_WC;
  };
  const std::vector<Case> cases = {
      {"chase", ChaseCamera({}).Update(wing.pose(), 0.0)},
      {"under the ground", LookAt(Vector3d(10, 10, -40), Vector3d(30, 40, 20))},
      {"beside the terrain", LookAt(Vector3d(260, 0, -2), Vector3d(150, 0, 6))},
      {"a hair above the grass", LookAt(Vector3d(60, 20, ground + 0.02), Vector3d(90, 40, ground))},
      {"inside the boulder", LookAt(Vector3d(70, -60, 22.6), Vector3d(80, -55, 22))},
      {"inside the wing", LookAt(wing.pose() * Vector3d(0, 0, 0), wing.pose() * Vector3d(0, 5, 0))},
      {"above the wing",
       LookAt(wing.pose() * Vector3d(0, 0, 0.5), wing.pose() * Vector3d(-2, 8, 0))}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    CameraView view;
    view.X_WC = c.X_WC;
    for (const Quality quality : {Quality::kPlain, Quality::kFast}) {
      // Colour alone (levels of detail, deferred shading in the fast look)
      // and the measurement images (drawn as given).
      for (const ImageKinds kinds :
           {ImageKinds(kColorImage), ImageKinds(kDepthImage | kSegmentationImage)}) {
        RenderSettings settings = RenderSettings::Preset(quality);
        settings.images = kinds;
        Frame culled, every_face;
        renderer->Render(view, {}, {&wing}, settings, &culled);
        settings.cull_hidden_back_faces = false;
        renderer->Render(view, {}, {&wing}, settings, &every_face);
        std::size_t differ = 0;
        for (std::size_t i = 0; i < culled.rgb.size(); ++i) {
          differ += culled.rgb[i] != every_face.rgb[i];
        }
        for (std::size_t i = 0; i < culled.depth_m.size(); ++i) {
          differ += culled.depth_m[i] != every_face.depth_m[i];
        }
        for (std::size_t i = 0; i < culled.segment.size(); ++i) {
          differ += culled.segment[i] != every_face.segment[i];
        }
        // (A pixel whose centre lies on a silhouette's edge may have gone to
        // the back face there: a few at most.)
        EXPECT_LE(differ, 15u) << int(quality) << " " << kinds;
      }
    }
  }
}

TEST(CameraTest, ChaseCameraAimsAtTheRobotAndFollowsWithoutOvershoot) {
  ChaseCamera chase({});
  Isometry3d X_WB = Eigen::Translation3d(10, 20, 60) * Eigen::AngleAxisd(0.7, Vector3d::UnitZ());
  CameraView view;
  for (int i = 0; i < 100; ++i) view.X_WC = chase.Update(X_WB, 0.05);
  const Eigen::Vector2d centre = Project(view, X_WB.translation());
  EXPECT_NEAR(centre.x(), 320.0, 0.5);
  EXPECT_NEAR(centre.y(), 240.0, 0.5);
  // A 50 m step: the camera closes on its new place monotonically.
  X_WB.translation() += Vector3d(50, 0, 0);
  ChaseCamera settled({});
  const Vector3d goal = settled.Update(X_WB, 0.0).translation();
  double last = 1e9;
  for (int i = 0; i < 60; ++i) {
    const double distance = (chase.Update(X_WB, 0.05).translation() - goal).norm();
    EXPECT_LT(distance, last);
    last = distance;
  }
  EXPECT_LT(last, 0.01);
  // Trailing: pan turns the camera about the robot; tilt raises it.
  const Isometry3d straight = TrailingPose(X_WB, 25, 8, {});
  const Isometry3d panned = TrailingPose(X_WB, 25, 8, {M_PI / 2, 0.0, 1.0});
  EXPECT_NEAR((straight.translation() - X_WB.translation()).norm(),
              (panned.translation() - X_WB.translation()).norm(), 1e-9);
  EXPECT_GT(TrailingPose(X_WB, 25, 8, {0.0, 0.3, 1.0}).translation().z(),
            straight.translation().z());
  // Zoom 2 doubles every off-centre offset in the image.
  CameraView wide;
  wide.X_WC = Isometry3d::Identity();  // looking along +x
  CameraView zoomed = wide;
  zoomed.fov_y_rad = ZoomedFov(wide.fov_y_rad, 2.0);
  const Vector3d p(100, 7, -5);
  const Eigen::Vector2d centre_px(320, 240);
  EXPECT_TRUE(
      (Project(zoomed, p) - centre_px).isApprox(2.0 * (Project(wide, p) - centre_px), 1e-9));
  EXPECT_NEAR(ZoomedFov(M_PI / 2, 2.0), 2.0 * std::atan(0.5), 1e-12);
}

TEST(CameraTest, BadViewsAreRefused) {
  CameraView view;
  view.width = 0;
  EXPECT_THROW(view.ValidateOrThrow(), std::invalid_argument);
  view.width = 100000;
  EXPECT_THROW(view.ValidateOrThrow(), std::invalid_argument);
  view.width = 640;
  view.fov_y_rad = 4.0;
  EXPECT_THROW(view.ValidateOrThrow(), std::invalid_argument);
}

// Lenses: square markers on a grid in front of a camera drawn through a
// Brown-Conrady and a fisheye lens. Points on the markers and in the gaps
// between them are projected by OpenCV (cv::projectPoints,
// cv::fisheye::projectPoints) with the same coefficients; every point whose
// projection lies more than 0.5 px (plus the half diagonal to its nearest
// pixel centre) from a marker's projected edge is seen there as what it is:
// each marker's edges are where OpenCV puts them, within 0.5 px.
TEST(RendererLensTest, MarkersLandWhereOpenCvProjectsThem) {
  testing::TempDir dir;
  constexpr double kHalf = 0.35, kPitch = 1.1, kDistance = 10.0;
  dir.Write("marker.obj",
            "o m\nv 0 -0.35 -0.35\nv 0 0.35 -0.35\nv 0 0.35 0.35\nv 0 -0.35 0.35\nf 1 2 3 4\n");
  std::ostringstream toml;
  std::vector<Vector3d> centres;
  for (int row = -4; row <= 4; ++row) {
    for (int column = -6; column <= 6; ++column) {
      const Vector3d c(kDistance, kPitch * column, kPitch * row);
      toml << "[[actor]]\nname = \"m" << centres.size() << "\"\nfile = \"marker.obj\"\n"
           << "position = [" << c.x() << ", " << c.y() << ", " << c.z() << "]\n";
      centres.push_back(c);
    }
  }
  const scene::Level level = scene::LoadLevel(dir.Write("level.toml", toml.str()));
  std::unique_ptr<Renderer> renderer = MakeRenderer();
  renderer->SetLevel(level, app::OpenCvTextureDecoder());
  Lens brown;
  brown.fx = 520.0, brown.fy = 515.0, brown.cx = 321.5, brown.cy = 238.25;
  brown.k1 = -0.28, brown.k2 = 0.09, brown.k3 = -0.01, brown.p1 = 0.0012, brown.p2 = -0.0008;
  Lens fisheye;
  fisheye.model = Lens::Model::kFisheye;
  fisheye.fx = fisheye.fy = 330.0, fisheye.cx = 319.5, fisheye.cy = 239.5;
  fisheye.k1 = 0.02, fisheye.k2 = -0.004, fisheye.k3 = 0.001, fisheye.k4 = -0.0002;
  for (const Lens& lens : {brown, fisheye}) {
    CameraView view;  // at the origin, looking along +x
    view.lens = lens;
    RenderSettings settings;
    settings.images = kSegmentationImage | kColorImage | kDepthImage;
    Frame frame;
    renderer->Render(view, {}, {}, settings, &frame);
    ASSERT_EQ(frame.width, 640);
    ASSERT_EQ(frame.segment.size(), 640u * 480u);
    // Points on the marker plane, and for each its nearest marker edge point.
    std::vector<cv::Point3d> points;  // OpenCV's camera frame: x right, y down, z forward
    std::vector<std::uint32_t> truth;
    for (double y = -7.0; y <= 7.0; y += 0.013) {
      for (double z = -4.9; z <= 4.9; z += 0.013) {
        const double col = std::round(y / kPitch), row = std::round(z / kPitch);
        const double dy = y - kPitch * col, dz = z - kPitch * row;
        const bool on = std::abs(dy) < kHalf && std::abs(dz) < kHalf && std::abs(col) <= 6 &&
                        std::abs(row) <= 4;
        // The nearest edge point of the marker this point is on or beside.
        double ey = y, ez = z;
        if (std::abs(std::abs(dy) - kHalf) < std::abs(std::abs(dz) - kHalf)) {
          ey = kPitch * col + std::copysign(kHalf, dy);
        } else {
          ez = kPitch * row + std::copysign(kHalf, dz);
        }
        points.emplace_back(-y, -z, kDistance);
        points.emplace_back(-ey, -ez, kDistance);
        truth.push_back(on ? std::uint32_t((row + 4) * 13 + (col + 6) + 1) : 0u);
      }
    }
    const cv::Matx33d K(lens.fx, 0, lens.cx, 0, lens.fy, lens.cy, 0, 0, 1);
    std::vector<cv::Point2d> pixels;
    if (lens.model == Lens::Model::kFisheye) {
      cv::fisheye::projectPoints(points, pixels, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K,
                                 cv::Vec4d(lens.k1, lens.k2, lens.k3, lens.k4));
    } else {
      cv::projectPoints(points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K,
                        std::vector<double>{lens.k1, lens.k2, lens.p1, lens.p2, lens.k3}, pixels);
    }
    int checked = 0, wrong = 0, on_markers = 0;
    for (std::size_t i = 0; i < truth.size(); ++i) {
      const cv::Point2d p = pixels[2 * i], edge = pixels[2 * i + 1];
      const int u = int(std::lround(p.x)), v = int(std::lround(p.y));
      if (u < 0 || u >= 640 || v < 0 || v >= 480) continue;
      if (cv::norm(p - edge) < 0.5 + 0.71) continue;  // too near an edge to tell
      ++checked;
      on_markers += truth[i] != 0;
      if (frame.segment[std::size_t(v) * 640 + std::size_t(u)] != truth[i]) ++wrong;
    }
    EXPECT_GT(checked, 200000) << lens.ModelName();
    EXPECT_GT(on_markers, 50000) << lens.ModelName();
    EXPECT_EQ(wrong, 0) << lens.ModelName();
    // Depth through the lens: the middle marker lies 10 m along the optical axis.
    EXPECT_NEAR(
        frame.depth_m[std::size_t(std::lround(lens.cy)) * 640 + std::size_t(std::lround(lens.cx))],
        kDistance, 0.01)
        << lens.ModelName();

    // The overlay through the lens, deferred and forward colour: a red mark
    // (6 source pixels wide) before each marker's centre lands where OpenCV
    // projects that centre.
    Overlay overlay;
    overlay.point_size_px = 6.f;
    std::vector<cv::Point3d> marks;
    for (const Vector3d& c : centres) {
      overlay.AddPoint(c - Vector3d(0.5, 0, 0), Eigen::Vector3f(1.f, 0.f, 0.f));
      marks.emplace_back(-c.y(), -c.z(), c.x() - 0.5);
    }
    std::vector<cv::Point2d> at;
    if (lens.model == Lens::Model::kFisheye) {
      cv::fisheye::projectPoints(marks, at, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K,
                                 cv::Vec4d(lens.k1, lens.k2, lens.k3, lens.k4));
    } else {
      cv::projectPoints(marks, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K,
                        std::vector<double>{lens.k1, lens.k2, lens.p1, lens.p2, lens.k3}, at);
    }
    for (const bool deferred : {true, false}) {
      settings.deferred = deferred;
      settings.images = kColorImage;
      renderer->Render(view, {}, {}, settings, &frame, &overlay);
      ASSERT_EQ(frame.rgb.size(), 3u * 640u * 480u);
      int red = 0, inside = 0;
      for (const cv::Point2d& p : at) {
        const int u = int(std::lround(p.x)), v = int(std::lround(p.y));
        if (u < 0 || u >= 640 || v < 0 || v >= 480) continue;
        ++inside;
        const std::uint8_t* rgb = &frame.rgb[3 * (std::size_t(v) * 640 + std::size_t(u))];
        red += rgb[0] == 255 && rgb[1] == 0 && rgb[2] == 0;
      }
      EXPECT_GT(inside, 80) << lens.ModelName();
      EXPECT_EQ(red, inside) << lens.ModelName() << (deferred ? ", deferred" : ", forward");
    }
  }
}

}  // namespace
}  // namespace sandbox::render
