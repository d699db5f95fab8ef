// RenderSettings' rules: each field the renderer once clamped silently is
// refused, naming the field and the value; the presets pass.

#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <stdexcept>
#include <string>

#include "sensors/render/renderer.h"

namespace sandbox::render {
namespace {

// The message ValidateOrThrow gives with one field changed, or "valid".
std::string ErrorWith(const std::function<void(RenderSettings*)>& change) {
  RenderSettings settings = RenderSettings::Preset(Quality::kHigh);
  change(&settings);
  try {
    settings.ValidateOrThrow();
  } catch (const std::invalid_argument& error) {
    return error.what();
  }
  return "valid";
}

TEST(RenderSettingsTest, ThePresetsAreValid) {
  for (const Quality q : {Quality::kPlain, Quality::kFast, Quality::kHigh}) {
    EXPECT_FALSE(RenderSettings::Preset(q).FindProblem().has_value());
  }
}

TEST(RenderSettingsTest, EachFieldOutOfItsRangeIsNamedWithItsValue) {
  constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(ErrorWith([](RenderSettings* s) { s->msaa_samples = 16; }),
            "RenderSettings::ValidateOrThrow(): 'msaa_samples' must be 0 (off), 1 (off) or 4 samples, got 16");
  EXPECT_EQ(ErrorWith([](RenderSettings* s) { s->msaa_samples = 4; }), "valid");
  EXPECT_EQ(ErrorWith([](RenderSettings* s) { s->anisotropy = 17; }),
            "RenderSettings::ValidateOrThrow(): 'anisotropy' must be 1 (off) to 16, got 17");
  EXPECT_EQ(ErrorWith([](RenderSettings* s) { s->lod_px = -0.5f; }),
            "RenderSettings::ValidateOrThrow(): 'lod_px' must be 0 (meshes as given) to 8 pixels, got -0.5");
  EXPECT_EQ(ErrorWith([](RenderSettings* s) { s->shadow_map_px = 100; }),
            "RenderSettings::ValidateOrThrow(): 'shadow_map_px' must be 256 to 8192 texels, got 100");
  EXPECT_EQ(ErrorWith([](RenderSettings* s) { s->shadow_map_px = 16384; }),
            "RenderSettings::ValidateOrThrow(): 'shadow_map_px' must be 256 to 8192 texels, got 16384");
  EXPECT_EQ(ErrorWith([](RenderSettings* s) { s->shadow_cascades = 0; }),
            "RenderSettings::ValidateOrThrow(): 'shadow_cascades' must be 1 to 4, got 0");
  EXPECT_EQ(ErrorWith([](RenderSettings* s) { s->shadow_cascades = 5; }),
            "RenderSettings::ValidateOrThrow(): 'shadow_cascades' must be 1 to 4, got 5");
  EXPECT_EQ(ErrorWith([&](RenderSettings* s) { s->shadow_distance_m = kNan; }),
            "RenderSettings::ValidateOrThrow(): 'shadow_distance_m' must be positive and finite, got nan");
  EXPECT_EQ(ErrorWith([](RenderSettings* s) { s->fog_end_m = s->fog_start_m; }),
            "RenderSettings::ValidateOrThrow(): 'fog_end_m' must be finite and beyond fog_start_m >= 0, got 300 .. "
            "300");
  EXPECT_EQ(ErrorWith([](RenderSettings* s) { s->sky_rgb.x() = 1.5f; }),
            "RenderSettings::ValidateOrThrow(): 'sky_rgb' must be three values from 0 to 1");
  EXPECT_EQ(ErrorWith([](RenderSettings* s) { s->sun_direction_W.setZero(); }),
            "RenderSettings::ValidateOrThrow(): 'sun_direction_W' must be a finite, non-zero direction");
  EXPECT_EQ(ErrorWith([](RenderSettings* s) { s->images = 0; }),
            "RenderSettings::ValidateOrThrow(): 'images' must name at least one image kind, and only known ones");
  EXPECT_EQ(ErrorWith([](RenderSettings* s) { s->images = 16; }),
            "RenderSettings::ValidateOrThrow(): 'images' must name at least one image kind, and only known ones");
}

}  // namespace
}  // namespace sandbox::render
