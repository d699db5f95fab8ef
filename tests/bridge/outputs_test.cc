// Outputs over LCM (memq://, one process): what a subscriber decodes is what
// the sensor measured, on <ROBOT>/<TOPIC>, tagged with its input.

#include "bridge/outputs.h"

#include <gtest/gtest.h>

#include "bridge/lcm_link.h"
#include "sandbox_msgs/range_t.hpp"
#include "scene/collision_world.h"
#include "scene/level.h"
#include "sensors/range_sensor.h"
#include "tests/test_util.h"

namespace sandbox::bridge {
namespace {

TEST(RobotOutputsTest, RangeReadingArrivesOnItsChannelWithItsSensorAndInput) {
  const scene::Level level = scene::LoadLevel(testing::SampleLevel());
  const scene::CollisionWorld world(level);
  sensors::RayCaster caster;
  LcmLink link("memq://");
  LatestInput subscriber(link, "ELAHA/RANGE");
  RobotOutputs outputs(link, "ELAHA");

  // Straight down from 500 m: the sample terrain is below, well within range.
  sensors::RangeSensorConfig altimeter;
  altimeter.range_m = 1000.0;
  const Eigen::Isometry3d X_WS(Eigen::Translation3d(3.0, -4.0, 500.0));
  const sensors::RangeReading reading = sensors::MeasureRange(altimeter, world, caster, {}, X_WS);
  ASSERT_TRUE(reading.hit);
  outputs.PublishRange("altimeter", reading, InputTag{42, 4200}, 123456);
  link.Drain();

  const std::vector<std::uint8_t>* bytes = subscriber.TakeNewest();
  ASSERT_NE(bytes, nullptr);
  sandbox_msgs::range_t message;
  ASSERT_EQ(message.decode(bytes->data(), 0, int(bytes->size())), int(bytes->size()));
  EXPECT_EQ(message.sensor, "altimeter");
  EXPECT_EQ(message.utime, 123456);
  EXPECT_EQ(message.input_seq, 42);
  EXPECT_EQ(message.input_utime, 4200);
  EXPECT_EQ(message.hit, 1);
  EXPECT_EQ(message.body, reading.body);
  // The ray as mounted, and the point where it stopped on it.
  EXPECT_DOUBLE_EQ(message.origin[0], 3.0);
  EXPECT_DOUBLE_EQ(message.origin[1], -4.0);
  EXPECT_DOUBLE_EQ(message.origin[2], 500.0);
  EXPECT_DOUBLE_EQ(message.direction[2], -1.0);
  EXPECT_NEAR(message.point[0], 3.0, 1e-4);
  EXPECT_NEAR(message.point[1], -4.0, 1e-4);
  EXPECT_NEAR(message.point[2], 500.0 - message.range_m, 1e-3);
  EXPECT_GT(message.normal[2], 0.0);  // the ground faces up
  EXPECT_EQ(outputs.published(), 1);
}

}  // namespace
}  // namespace sandbox::bridge
