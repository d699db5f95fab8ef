// The IMU against analytic motions (noise off), WGS84's published normal
// gravity, and its noise model's statistics over 100,000 samples.

#include "sensors/imu.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <vector>

#include "scene/collision_world.h"
#include "scene/level.h"
#include "sensors/normal_gravity.h"
#include "sensors/pose_track.h"

namespace sandbox::sensors {
namespace {

using Eigen::Vector3d;
constexpr double kG0 = 9.80665;  // standard gravity

// Runs `imu` on poses at `pose_hz` from time 0 for `poses` poses, X(t) given;
// every sample, with its time in seconds.
struct Sample {
  double t;
  Vector3d force, rate;
};
std::vector<Sample> Fly(Imu& imu, double pose_hz, int poses,
                        const std::function<Eigen::Isometry3d(double)>& X_at,
                        const scene::LocalTangentPlane* geodetic = nullptr,
                        std::int64_t utime0 = 0) {
  static const scene::Level empty;
  static const scene::CollisionWorld world(empty);
  RayCaster caster(1);
  std::vector<Sample> samples;
  ImuSamples out;
  for (int k = 0; k < poses; ++k) {
    const std::int64_t utime = utime0 + std::llround(double(k) * 1e6 / pose_hz);
    const double t = double(utime - utime0) * 1e-6;
    const Eigen::Isometry3d X = X_at(t);
    const SensorContext at{world, caster, {}, X, X, nullptr, t, k, utime, geodetic};
    imu.Run(at, &out);
    for (std::size_t i = 0; i < out.utime.size(); ++i) {
      samples.push_back(
          {double(out.utime[i] - utime0) * 1e-6, out.specific_force_S[i], out.angular_rate_S[i]});
    }
  }
  return samples;
}

ImuConfig Rate(double hz) {
  ImuConfig config;
  config.rate_hz = hz;
  return config;
}

// A level circle at speed v and radius r, counter-clockwise, the body's x
// along the velocity: v^2 / r towards the centre (the body's +y), 1 g up,
// and the turn rate v / r about z. Samples between the poses too.
TEST(ImuTest, ALevelCircleGivesTheCentripetalAccelerationAndOneGUp) {
  const double v = 50.0, r = 500.0, omega = v / r;
  auto circle = [&](double t) {
    Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
    X.translation() = Vector3d(r * std::sin(omega * t), r - r * std::cos(omega * t), 1000.0);
    X.linear() = Eigen::AngleAxisd(omega * t, Vector3d::UnitZ()).toRotationMatrix();
    return X;
  };
  Imu imu(Rate(4000.0));  // four samples a pose at 1 kHz poses
  const std::vector<Sample> samples = Fly(imu, 1000.0, 300, circle);
  ASSERT_EQ(samples.size(), 299u * 4u);
  double worst = 0.0;
  for (std::size_t i = 12; i < samples.size(); ++i) {  // from the fourth pose: the cubic
    const Vector3d expected_force(0.0, v * v / r, kG0);
    const Vector3d expected_rate(0.0, 0.0, omega);
    worst = std::max(worst, (samples[i].force - expected_force).cwiseAbs().maxCoeff());
    EXPECT_LT((samples[i].rate - expected_rate).cwiseAbs().maxCoeff(), 1e-9) << i;
  }
  EXPECT_LT(worst, 1e-6);
  // Sample times: every 250 us after the first pose.
  for (std::size_t i = 0; i < samples.size(); ++i) {
    EXPECT_NEAR(samples[i].t, 0.00025 * double(i + 1), 1e-12) << i;
  }
}

// A constant-rate roll about a tilted axis: that rate, in the body frame;
// the specific force is gravity's reaction rotated into the rolling body.
TEST(ImuTest, AConstantRateRollGivesThatRate) {
  const Vector3d axis = Vector3d(1.0, 0.2, -0.1).normalized();
  const double rate = 0.7;  // rad/s
  const Eigen::Matrix3d R0 = Eigen::AngleAxisd(0.3, Vector3d::UnitY()).toRotationMatrix();
  auto roll = [&](double t) {
    Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
    X.translation() = Vector3d(5.0, -3.0, 20.0);
    X.linear() = R0 * Eigen::AngleAxisd(rate * t, axis).toRotationMatrix();
    return X;
  };
  Imu imu(Rate(0.0));  // one sample a pose
  const std::vector<Sample> samples = Fly(imu, 200.0, 400, roll);
  ASSERT_EQ(samples.size(), 399u);
  for (std::size_t i = 2; i < samples.size(); ++i) {
    EXPECT_LT((samples[i].rate - rate * axis).norm(), 1e-9) << i;
    const Vector3d up_in_body = roll(samples[i].t).linear().transpose() * Vector3d(0, 0, kG0);
    EXPECT_LT((samples[i].force - up_in_body).norm(), 1e-9) << i;
  }
}

// WGS84 normal gravity as TR8350.2 publishes it: 9.7803253359 at the equator,
// 9.8321849379 at the poles; 3.0877e-6 s^-2 less a metre up (the free-air
// gradient at 45 degrees, to 0.1%).
TEST(ImuTest, NormalGravityIsWgs84s) {
  EXPECT_NEAR(NormalGravity(0.0, 0.0), 9.7803253359, 1e-9);
  EXPECT_NEAR(NormalGravity(90.0, 0.0), 9.8321849379, 1e-9);
  EXPECT_NEAR(NormalGravity(-90.0, 0.0), 9.8321849379, 1e-9);
  EXPECT_NEAR((NormalGravity(45.0, 0.0) - NormalGravity(45.0, 1000.0)) / 1000.0, 3.0877e-6, 3e-9);
  // At rest on a level with an anchor: gravity's reaction, up.
  const scene::LocalTangentPlane frame({47.0, 8.0, 500.0});
  Imu imu(Rate(100.0));
  const std::vector<Sample> samples = Fly(
      imu, 100.0, 5, [](double) { return Eigen::Isometry3d::Identity(); }, &frame);
  ASSERT_FALSE(samples.empty());
  EXPECT_LT((samples.back().force - Vector3d(0, 0, NormalGravity(47.0, 500.0))).norm(), 1e-9);
  // 100 km east the plumb line leans back towards the anchor by ~0.9 degrees.
  const Vector3d g_east = GravityInWorld(frame, Vector3d(100e3, 0.0, 0.0));
  EXPECT_NEAR(std::atan2(-g_east.x(), -g_east.z()) * 180.0 / M_PI, 0.9, 0.05);
}

// Epoch time stamps keep their microseconds: the same circle flown from
// 2026 gives the same readings.
TEST(ImuTest, EpochTimeStampsGiveTheSameReadings) {
  auto climb = [](double t) {
    Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
    X.translation() = Vector3d(30.0 * t, 0.0, 0.5 * 2.0 * t * t);  // 2 m/s^2 up
    return X;
  };
  Imu from_zero(Rate(500.0)), from_epoch(Rate(500.0));
  const auto a = Fly(from_zero, 100.0, 50, climb);
  const auto b = Fly(from_epoch, 100.0, 50, climb, nullptr, 1796000000000000);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 5; i < a.size(); ++i) {
    EXPECT_NEAR(a[i].force.z(), kG0 + 2.0, 1e-7) << i;
    EXPECT_NEAR(b[i].force.z(), kG0 + 2.0, 1e-7) << i;
  }
}

// The errors: white noise of density n is n sqrt(rate) per sample; a bias
// walk of b steps b sqrt(1 / rate) per sample; both within 3% over 100,000
// samples. Saturation clips. One seed repeats exactly; another differs.
TEST(ImuTest, NoiseAndBiasDriftHaveTheConfiguredStatistics) {
  const double rate_hz = 1000.0;
  ImuConfig config = Rate(rate_hz);
  config.accel.noise_density = 0.002;   // m/s^2/sqrt(Hz)
  config.gyro.bias_random_walk = 4e-5;  // rad/s^2/sqrt(Hz)
  config.seed = 11;
  auto rest = [](double) { return Eigen::Isometry3d::Identity(); };
  Imu imu(config);
  const std::vector<Sample> samples = Fly(imu, 100.0, 10001, rest);
  ASSERT_EQ(samples.size(), 100000u);
  for (int axis = 0; axis < 3; ++axis) {
    const double truth = axis == 2 ? kG0 : 0.0;
    double sum = 0.0, sum2 = 0.0, step2 = 0.0;
    for (std::size_t i = 0; i < samples.size(); ++i) {
      const double e = samples[i].force[axis] - truth;
      sum += e, sum2 += e * e;
      if (i > 0) step2 += std::pow(samples[i].rate[axis] - samples[i - 1].rate[axis], 2);
    }
    const double n = double(samples.size());
    const double sigma = std::sqrt(sum2 / n - std::pow(sum / n, 2));
    EXPECT_NEAR(sigma / (0.002 * std::sqrt(rate_hz)), 1.0, 0.03) << axis;
    const double step_sigma = std::sqrt(step2 / (n - 1.0));
    EXPECT_NEAR(step_sigma / (4e-5 / std::sqrt(rate_hz)), 1.0, 0.03) << axis;
  }
  Imu same(config);
  const std::vector<Sample> again = Fly(same, 100.0, 10001, rest);
  config.seed = 12;
  Imu other(config);
  const std::vector<Sample> different = Fly(other, 100.0, 10001, rest);
  for (std::size_t i = 0; i < samples.size(); i += 997) {
    EXPECT_EQ(again[i].force, samples[i].force) << i;
    EXPECT_EQ(again[i].rate, samples[i].rate) << i;
    EXPECT_NE(different[i].force, samples[i].force) << i;
  }
  // A saturation at 5 m/s^2 clips gravity's 9.8.
  ImuConfig clipped = Rate(100.0);
  clipped.accel.saturation = 5.0;
  Imu saturated(clipped);
  EXPECT_EQ(Fly(saturated, 100.0, 3, rest).back().force, Vector3d(0, 0, 5.0));
}

// Several samples a pose at rates that do not divide the poses' period; a
// pose that went back in time or came after a long gap starts afresh.
TEST(ImuTest, SamplesFallOnItsOwnClock) {
  Imu imu(Rate(300.0));
  auto rest = [](double) { return Eigen::Isometry3d::Identity(); };
  const std::vector<Sample> samples = Fly(imu, 100.0, 11, rest);  // 0.1 s after the first
  ASSERT_EQ(samples.size(), 30u);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    EXPECT_NEAR(samples[i].t, double(i + 1) / 300.0, 0.5e-6) << i;
  }
  static const scene::Level empty;
  static const scene::CollisionWorld world(empty);
  RayCaster caster(1);
  ImuSamples out;
  Imu fresh(Rate(100.0));
  const Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  auto run = [&](std::int64_t utime) {
    fresh.Run({world, caster, {}, X, X, nullptr, 0.0, 0, utime, nullptr}, &out);
    return out.utime.size();
  };
  EXPECT_EQ(run(-1), 0u);       // no pose yet
  EXPECT_EQ(run(0), 0u);        // the first pose: nothing before it
  EXPECT_EQ(run(0), 0u);        // no new pose
  EXPECT_EQ(run(20000), 2u);    // 10 and 20 ms
  EXPECT_EQ(run(10000), 0u);    // back in time: afresh
  EXPECT_EQ(run(30000), 2u);    // 20 and 30 ms
  EXPECT_EQ(run(5000000), 0u);  // after a 5 s gap: afresh
  EXPECT_EQ(run(5010000), 1u);
}

}  // namespace
}  // namespace sandbox::sensors
