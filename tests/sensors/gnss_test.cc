// The GNSS receiver against PROJ's own transforms (topocentric and
// geocentric, as libproj computes them) along a 200 km flight, its latency,
// and its noise's statistics over 100,000 fixes.

#include "sensors/gnss.h"

#include <gtest/gtest.h>
#include <proj.h>

#include <cmath>
#include <functional>
#include <vector>

#include "scene/collision_world.h"
#include "scene/level.h"

namespace sandbox::sensors {
namespace {

using Eigen::Vector3d;
constexpr double kDeg = M_PI / 180.0;
const scene::GeodeticPoint kAnchor{47.0, 8.0, 500.0};

// Runs `gnss` on poses at `pose_hz` for `poses` poses, position p(t); each
// tick's released fixes.
std::vector<std::vector<GnssFix>> Fly(Gnss& gnss, double pose_hz, int poses,
                                      const std::function<Vector3d(double)>& p_at,
                                      const scene::LocalTangentPlane* frame) {
  static const scene::Level empty;
  static const scene::CollisionWorld world(empty);
  RayCaster caster(1);
  std::vector<std::vector<GnssFix>> ticks;
  GnssFixes out;
  for (int k = 0; k < poses; ++k) {
    const std::int64_t utime = std::llround(double(k) * 1e6 / pose_hz);
    Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
    X.translation() = p_at(double(utime) * 1e-6);
    gnss.Run({world, caster, {}, X, X, nullptr, 0.0, k, utime, frame}, &out);
    ticks.push_back(out.fixes);
  }
  return ticks;
}

// PROJ: world (east, north, up at the anchor) to longitude, latitude
// (radians) and ellipsoidal height, and to ECEF.
struct Proj {
  PJ_CONTEXT* context = proj_context_create();
  PJ* to_geodetic = proj_create(
      context,
      "+proj=pipeline +step +inv +proj=topocentric +lat_0=47 +lon_0=8 +h_0=500 +ellps=WGS84 "
      "+step +inv +proj=cart +ellps=WGS84");
  PJ* to_ecef =
      proj_create(context,
                  "+proj=pipeline +step +inv +proj=topocentric +lat_0=47 +lon_0=8 +h_0=500 "
                  "+ellps=WGS84");
  ~Proj() {
    proj_destroy(to_geodetic);
    proj_destroy(to_ecef);
    proj_context_destroy(context);
  }
  PJ_COORD Forward(PJ* pipeline, const Vector3d& p) const {
    return proj_trans(pipeline, PJ_FWD, proj_coord(p.x(), p.y(), p.z(), 0.0));
  }
};

// A 200 km flight from the anchor, 60 degrees from north, climbing at 10 m/s
// at 250 m/s: every fix equals PROJ's transform of the same point to 1 mm,
// and its velocity PROJ's ECEF velocity turned into north, east, down at
// PROJ's latitude and longitude, to 1 mm/s.
TEST(GnssTest, FixesAlongA200KmFlightAreProjsTransformOfThePoints) {
  Proj proj;
  ASSERT_NE(proj.to_geodetic, nullptr) << proj_errno_string(proj_context_errno(proj.context));
  ASSERT_NE(proj.to_ecef, nullptr);
  const scene::LocalTangentPlane frame(kAnchor);
  const Vector3d velocity(250.0 * std::sin(60 * kDeg), 250.0 * std::cos(60 * kDeg), 10.0);
  auto p_at = [&](double t) -> Vector3d { return Vector3d(0.0, 0.0, 1000.0) + t * velocity; };
  GnssConfig config;
  config.rate_hz = 1.0;
  Gnss gnss(config);
  const auto ticks = Fly(gnss, 10.0, 8001, p_at, &frame);  // 800 s: 200 km
  int fixes = 0;
  double worst_m = 0.0, worst_v = 0.0;
  for (const auto& tick : ticks) {
    for (const GnssFix& fix : tick) {
      ++fixes;
      const double t = double(fix.utime) * 1e-6;
      const PJ_COORD geo = proj.Forward(proj.to_geodetic, p_at(t));
      const double lat = geo.lpz.phi, lon = geo.lpz.lam;
      const double north_m = (fix.latitude_deg * kDeg - lat) * 6.37e6;
      const double east_m = (fix.longitude_deg * kDeg - lon) * 6.37e6 * std::cos(lat);
      worst_m = std::max(
          {worst_m, std::abs(north_m), std::abs(east_m), std::abs(fix.height_m - geo.lpz.z)});
      // Velocity: PROJ's ECEF a millisecond either side, in NED at PROJ's point.
      const PJ_COORD a = proj.Forward(proj.to_ecef, p_at(t - 1e-3));
      const PJ_COORD b = proj.Forward(proj.to_ecef, p_at(t + 1e-3));
      const Vector3d v_ecef =
          (Vector3d(b.xyz.x, b.xyz.y, b.xyz.z) - Vector3d(a.xyz.x, a.xyz.y, a.xyz.z)) / 2e-3;
      const Vector3d north(-std::sin(lat) * std::cos(lon), -std::sin(lat) * std::sin(lon),
                           std::cos(lat));
      const Vector3d east(-std::sin(lon), std::cos(lon), 0.0);
      const Vector3d down(-std::cos(lat) * std::cos(lon), -std::cos(lat) * std::sin(lon),
                          -std::sin(lat));
      const Vector3d ned(north.dot(v_ecef), east.dot(v_ecef), down.dot(v_ecef));
      worst_v = std::max(worst_v, (fix.velocity_ned - ned).cwiseAbs().maxCoeff());
    }
  }
  EXPECT_EQ(fixes, 800);
  EXPECT_LT(worst_m, 1e-3);
  EXPECT_LT(worst_v, 1e-3);
}

// A fix taken at T comes out with the first pose at or after T + latency,
// stamped T; without a geodetic frame there is none.
TEST(GnssTest, AFixComesOutItsLatencyAfterItWasTaken) {
  const scene::LocalTangentPlane frame(kAnchor);
  GnssConfig config;
  config.rate_hz = 10.0;
  config.latency_s = 0.25;
  Gnss gnss(config);
  const auto ticks = Fly(
      gnss, 100.0, 201, [](double t) { return Vector3d(t, 0, 0); }, &frame);
  int fixes = 0;
  for (std::size_t k = 0; k < ticks.size(); ++k) {
    for (const GnssFix& fix : ticks[k]) {
      ++fixes;
      EXPECT_EQ(fix.utime % 100000, 0);                        // on the 10 Hz clock
      EXPECT_EQ(std::int64_t(k) * 10000, fix.utime + 250000);  // the tick of T + 0.25 s
    }
  }
  EXPECT_EQ(fixes, 17);  // those of 0.1 to 1.7 s have come out by 2 s
  Gnss blind(config);
  for (const auto& tick : Fly(
           blind, 100.0, 50, [](double) { return Vector3d::Zero(); }, nullptr)) {
    EXPECT_TRUE(tick.empty());
  }
}

// Noise: north and east each with the horizontal sigma, up with the vertical
// one, velocity with its own; within 3% over 100,000 fixes; one seed repeats.
TEST(GnssTest, NoiseHasTheConfiguredSigmas) {
  const scene::LocalTangentPlane frame(kAnchor);
  GnssConfig config;
  config.horizontal_sigma_m = 1.5;
  config.vertical_sigma_m = 3.0;
  config.velocity_sigma_m_s = 0.1;
  config.seed = 4;
  Gnss gnss(config);
  const auto ticks = Fly(
      gnss, 1000.0, 100001, [](double) { return Vector3d::Zero(); }, &frame);
  std::vector<Vector3d> offsets, velocities;
  for (const auto& tick : ticks) {
    for (const GnssFix& fix : tick) {
      offsets.push_back(frame.ToWorld({fix.latitude_deg, fix.longitude_deg, fix.height_m}));
      velocities.push_back(fix.velocity_ned);
    }
  }
  ASSERT_EQ(offsets.size(), 100000u);
  auto sigma = [](const std::vector<Vector3d>& values, int axis) {
    double sum = 0.0, sum2 = 0.0;
    for (const Vector3d& v : values) sum += v[axis], sum2 += v[axis] * v[axis];
    const double n = double(values.size());
    return std::sqrt(sum2 / n - (sum / n) * (sum / n));
  };
  EXPECT_NEAR(sigma(offsets, 0) / 1.5, 1.0, 0.03);
  EXPECT_NEAR(sigma(offsets, 1) / 1.5, 1.0, 0.03);
  EXPECT_NEAR(sigma(offsets, 2) / 3.0, 1.0, 0.03);
  for (int axis = 0; axis < 3; ++axis) EXPECT_NEAR(sigma(velocities, axis) / 0.1, 1.0, 0.03);
  Gnss again(config);
  const auto repeat = Fly(
      again, 1000.0, 100, [](double) { return Vector3d::Zero(); }, &frame);
  for (std::size_t k = 1; k < repeat.size(); ++k) {
    EXPECT_EQ(repeat[k][0].latitude_deg, ticks[k][0].latitude_deg) << k;
  }
}

}  // namespace
}  // namespace sandbox::sensors
