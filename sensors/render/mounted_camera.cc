#include "sensors/render/mounted_camera.h"

#include <array>
#include <cmath>
#include <stdexcept>
#include <utility>
#include <vector>

#include "scene/settings.h"

namespace sandbox::render {
namespace {

constexpr std::array<std::pair<CameraKind, std::string_view>, 4> kCameraTypes{{
    {CameraKind::kChase, "chase"},
    {CameraKind::kTrailing, "trailing"},
    {CameraKind::kPayload, "payload"},
    {CameraKind::kFixed, "fixed"},
}};

CameraKind ParseCameraKind(const scene::SensorSpec& spec) {
  std::vector<std::string_view> types;
  for (const auto& [kind, type] : kCameraTypes) {
    if (type == spec.type) return kind;
    types.push_back(type);
  }
  throw scene::LevelError(spec.settings.Where("type") + "'type' must be " +
                          scene::ChoiceList(types) + ", got '" + spec.type + "'");
}

// quality, shadows, fxaa, msaa, haze, anisotropy, lod_px, cull_hidden_back_faces,
// images: the camera's look.
void ReadLook(const scene::SensorSpec& spec, scene::SettingsReader* read, RenderSettings* look) {
  try {
    *look = RenderSettings::Preset(ParseQuality(read->Text("quality", "fast")));
  } catch (const std::invalid_argument& error) {
    throw scene::LevelError(spec.settings.Where("quality") + error.what());
  }
  look->shadows = read->Flag("shadows", look->shadows);
  look->haze = read->Flag("haze", look->haze);
  look->fxaa = read->Flag("fxaa", look->fxaa);
  look->msaa_samples = read->Whole("msaa", look->msaa_samples);
  look->anisotropy = read->Whole("anisotropy", look->anisotropy);
  const double lod_px = read->Number("lod_px", look->lod_px);
  look->lod_px = float(lod_px);
  look->cull_hidden_back_faces = read->Flag("cull_hidden_back_faces", look->cull_hidden_back_faces);
  look->images = kColorImage;
  if (read->Has("images")) {
    look->images = 0;
    for (const std::string& word : read->Texts("images")) {
      try {
        look->images |= ParseImageKind(word);
      } catch (const std::invalid_argument& error) {
        read->Fail("images", error.what());
      }
    }
    if (look->images == 0) read->Fail("images", "'images' must name at least one image kind");
  }
  // RenderSettings' own rules, named by the manifest's keys.
  if (const auto problem = look->FindProblem()) {
    const std::string key = problem->field == "msaa_samples" ? "msaa" : problem->field;
    read->Fail(key, "'" + key + "' " + problem->why);
  }
}

// A payload or fixed camera's `lens` and its intrinsics and coefficients
// (docs/reference/cameras.md); the focal length defaults to the pinhole's of
// fov_deg, the centre to the image's. Checked against the image's size.
void ReadLens(const scene::SensorSpec& spec, CameraKind kind, scene::SettingsReader* read,
              CameraView* view) {
  if (!read->Has("lens")) return;
  const std::string model = read->Text("lens", "");
  if (model != "brown_conrady" && model != "fisheye") {
    read->Fail("lens", "'lens' must be brown_conrady or fisheye, got '" + model + "'");
  }
  if (kind != CameraKind::kPayload && kind != CameraKind::kFixed) {
    read->Fail("lens", "a lens is for payload and fixed cameras");
  }
  Lens lens;
  lens.model = model == "fisheye" ? Lens::Model::kFisheye : Lens::Model::kBrownConrady;
  const double f = 0.5 * view->height / std::tan(0.5 * view->fov_y_rad);
  lens.fx = read->Number("fx", f), lens.fy = read->Number("fy", f);
  lens.cx = read->Number("cx", 0.5 * view->width - 0.5);
  lens.cy = read->Number("cy", 0.5 * view->height - 0.5);
  lens.k1 = read->Number("k1", 0.0), lens.k2 = read->Number("k2", 0.0);
  lens.k3 = read->Number("k3", 0.0);
  const double k4 = read->Number("k4", 0.0), p1 = read->Number("p1", 0.0);
  const double p2 = read->Number("p2", 0.0);
  if (lens.model == Lens::Model::kFisheye) {
    if (p1 != 0.0 || p2 != 0.0) read->Fail(p1 != 0.0 ? "p1" : "p2", "a fisheye lens has no p1, p2");
    lens.k4 = k4;
  } else {
    if (k4 != 0.0) read->Fail("k4", "'k4' is for a fisheye lens");
    lens.p1 = p1, lens.p2 = p2;
  }
  try {
    lens.ValidateOrThrow(view->width, view->height);
  } catch (const std::invalid_argument& error) {
    const std::string what = error.what();
    const std::string key = what.substr(0, what.find(' '));
    throw scene::LevelError(spec.settings.Where(read->Has(key) ? key : "lens") + what);
  }
  view->lens = lens;
}

}  // namespace

Eigen::Isometry3d MountedCamera::Pose(const scene::RobotState& state, ChaseCamera* chase_state,
                                      const TrailingCommand& command, double dt_s) const {
  switch (kind) {
    case CameraKind::kChase:
      return chase_state->Update(state.pose(), dt_s);
    case CameraKind::kTrailing:
      return TrailingPose(state.pose(), trailing_distance_m, trailing_height_m, command);
    case CameraKind::kFixed:
      return spec.X_MS;
    case CameraKind::kPayload:
      break;
  }
  return state.MountPose(spec);
}

std::vector<MountedCamera> MakeRobotCameras(const scene::Level& level) {
  std::vector<MountedCamera> cameras;
  for (std::size_t r = 0; r < level.robots.size(); ++r) {
    for (const scene::SensorSpec& spec : level.robots[r].cameras) {
      scene::SettingsReader read(spec.settings);
      MountedCamera camera;
      camera.spec = spec;
      camera.kind = ParseCameraKind(spec);
      camera.robot = static_cast<int>(r);
      camera.view.width = read.Whole("width", 640);
      camera.view.height = read.Whole("height", 480);
      camera.view.fov_y_rad = read.Number("fov_deg", 60.0) * M_PI / 180.0;
      camera.view.near_m = read.Number("near_m", 0.1);
      camera.view.far_m = read.Number("far_m", 2000.0);
      camera.chase.arm_length_m = read.Number("arm_length_m", camera.chase.arm_length_m);
      camera.chase.arm_height_m = read.Number("arm_height_m", camera.chase.arm_height_m);
      camera.chase.position_lag_s = read.Number("position_lag_s", camera.chase.position_lag_s);
      camera.chase.rotation_lag_s = read.Number("rotation_lag_s", camera.chase.rotation_lag_s);
      camera.trailing_distance_m = read.Number("distance_m", camera.trailing_distance_m);
      camera.trailing_height_m = read.Number("height_m", camera.trailing_height_m);
      ReadLook(spec, &read, &camera.look);
      if (read.Flag("depth", camera.kind == CameraKind::kPayload))
        camera.look.images |= kDepthImage;
      camera.overlay = read.Flag("overlay", false);
      camera.overlay_stub_m = read.Number("overlay_stub_m", 0.0);
      if (!(camera.overlay_stub_m >= 0.0 && camera.overlay_stub_m <= 100.0)) {
        throw scene::LevelError(spec.Where() + "overlay_stub_m must be 0 (points) to 100 m");
      }
      const std::string colour = read.Text("overlay_colour", "occupancy");
      if (colour != "occupancy" && colour != "surface") {
        read.Fail("overlay_colour",
                  "'overlay_colour' must be occupancy or surface, got '" + colour + "'");
      }
      camera.overlay_colour =
          colour == "surface" ? SampleColour::kSurface : SampleColour::kOccupancy;
      ReadLens(spec, camera.kind, &read, &camera.view);
      // The pixels the camera may have: a documented default, raised to a bound.
      const double pixel_budget =
          read.Number("pixel_budget", double(CameraView::kDefaultPixelBudget));
      read.RejectUnknownKeys(spec.type + " camera");
      try {
        camera.view.ValidateOrThrow();
      } catch (const std::invalid_argument& error) {
        throw scene::LevelError(spec.Where() + error.what());
      }
      if (!(pixel_budget >= 1.0 && pixel_budget <= double(CameraView::kMaxPixelBudget))) {
        throw scene::LevelError(spec.Where() + "pixel_budget must be 1 to " +
                                std::to_string(CameraView::kMaxPixelBudget) + ", got " +
                                std::to_string(pixel_budget));
      }
      const double pixels = double(camera.view.width) * double(camera.view.height);
      if (pixels > pixel_budget) {
        throw scene::LevelError(
            spec.Where() + std::to_string(camera.view.width) + " x " +
            std::to_string(camera.view.height) + " = " + std::to_string(std::int64_t(pixels)) +
            " pixels, over pixel_budget " + std::to_string(std::int64_t(pixel_budget)));
      }
      cameras.push_back(std::move(camera));
    }
  }
  return cameras;
}

}  // namespace sandbox::render
