// RenderSettings' rules, in one place: the manifest's camera keys and the
// renderer both hold a look to them.
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "sensors/render/renderer.h"

namespace sandbox::render {

Quality ParseQuality(const std::string& word) {
  if (word == "plain") return Quality::kPlain;
  if (word == "fast") return Quality::kFast;
  if (word == "high") return Quality::kHigh;
  throw std::invalid_argument("quality must be \"fast\" or \"high\" (or \"plain\"), got '" + word +
                              "'");
}

RenderSettings RenderSettings::Preset(Quality quality) {
  RenderSettings settings;
  settings.shadows = quality == Quality::kHigh;
  settings.msaa_samples = 0;
  settings.fxaa = quality == Quality::kHigh;
  settings.gamma_correct = quality != Quality::kPlain;
  settings.materials = quality != Quality::kPlain;
  return settings;
}

namespace {

std::string Text(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

}  // namespace

std::optional<RenderSettings::Problem> RenderSettings::FindProblem() const {
  if (msaa_samples != 0 && msaa_samples != 1 && msaa_samples != 4) {
    return Problem{"msaa_samples",
                   "must be 0 (off), 1 (off) or 4 samples, got " + std::to_string(msaa_samples)};
  }
  if (anisotropy < 1 || anisotropy > 16) {
    return Problem{"anisotropy", "must be 1 (off) to 16, got " + std::to_string(anisotropy)};
  }
  if (!(lod_px >= 0.f && lod_px <= 8.f)) {
    return Problem{"lod_px", "must be 0 (meshes as given) to 8 pixels, got " + Text(lod_px)};
  }
  if (shadow_map_px < 256 || shadow_map_px > 8192) {
    return Problem{"shadow_map_px",
                   "must be 256 to 8192 texels, got " + std::to_string(shadow_map_px)};
  }
  if (shadow_cascades < 1 || shadow_cascades > 4) {
    return Problem{"shadow_cascades", "must be 1 to 4, got " + std::to_string(shadow_cascades)};
  }
  if (!(std::isfinite(shadow_distance_m) && shadow_distance_m > 0.0)) {
    return Problem{"shadow_distance_m",
                   "must be positive and finite, got " + Text(shadow_distance_m)};
  }
  if (!(std::isfinite(fog_start_m) && std::isfinite(fog_end_m) && fog_start_m >= 0.f &&
        fog_end_m > fog_start_m)) {
    return Problem{"fog_end_m", "must be finite and beyond fog_start_m >= 0, got " +
                                    Text(fog_start_m) + " .. " + Text(fog_end_m)};
  }
  if (!(sky_rgb.allFinite() && sky_rgb.minCoeff() >= 0.f && sky_rgb.maxCoeff() <= 1.f)) {
    return Problem{"sky_rgb", "must be three values from 0 to 1"};
  }
  if (!(sun_direction_W.allFinite() && sun_direction_W.norm() > 1e-6f)) {
    return Problem{"sun_direction_W", "must be a finite, non-zero direction"};
  }
  constexpr ImageKinds kKnown = kColorImage | kDepthImage | kSegmentationImage | kNormalsImage;
  if (images == 0 || (images & ~kKnown) != 0) {
    return Problem{"images", "must name at least one image kind, and only known ones"};
  }
  return std::nullopt;
}

void RenderSettings::ValidateOrThrow() const {
  if (const auto problem = FindProblem()) {
    throw std::invalid_argument("RenderSettings::ValidateOrThrow(): '" + problem->field + "' " +
                                problem->why);
  }
}

}  // namespace sandbox::render
