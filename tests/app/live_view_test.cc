// The live view's keys: codes to keys, and what each key does to the controls.

#include "app/live_view.h"

#include <gtest/gtest.h>

#include <cmath>

namespace sandbox::app {
namespace {

TEST(ViewControlsTest, KeysStepPanTiltZoomWithinLimitsAndCycleCameras) {
  EXPECT_EQ(KeyFromCode('a'), ViewKey::kPanLeft);
  EXPECT_EQ(KeyFromCode(0xff53), ViewKey::kPanRight);  // X11 right arrow
  EXPECT_EQ(KeyFromCode(27), ViewKey::kQuit);          // Esc
  EXPECT_FALSE(KeyFromCode('x').has_value());
  ViewControls controls;
  controls.Apply(ViewKey::kPanLeft, 2);
  controls.Apply(ViewKey::kPanLeft, 2);
  EXPECT_NEAR(controls.steer.pan_rad, 10 * M_PI / 180, 1e-12);
  for (int i = 0; i < 40; ++i) controls.Apply(ViewKey::kTiltUp, 2);
  EXPECT_NEAR(controls.steer.tilt_rad, 80 * M_PI / 180, 1e-12);  // clamped
  controls.Apply(ViewKey::kZoomOut, 2);
  EXPECT_EQ(controls.steer.zoom, 1.0);  // never wider than the camera's own field of view
  controls.Apply(ViewKey::kZoomIn, 2);
  EXPECT_NEAR(controls.steer.zoom, 1.25, 1e-12);
  controls.Apply(ViewKey::kNextCamera, 2);
  EXPECT_EQ(controls.camera, 1);
  controls.Apply(ViewKey::kNextCamera, 2);
  EXPECT_EQ(controls.camera, 0);
  controls.Apply(ViewKey::kPause, 2);
  EXPECT_TRUE(controls.paused);
  controls.Apply(ViewKey::kPause, 2);
  EXPECT_FALSE(controls.paused);
}

}  // namespace
}  // namespace sandbox::app
