// The instruments' cost a tick: an IMU on a circling robot at 1 kHz output,
// from poses at 1 kHz (a sample a tick) and at 100 Hz (ten a tick), noise off
// and on, standard gravity and WGS84's at a geodetic anchor; a GNSS receiver
// at 1 kHz through the anchor, noise on; an air data computer at 1 kHz, noise
// and Dryden gusts on; against the
// issue's budget of 10 us a tick, and beside the cheapest ray sensor (one
// single ray on the sample level) run in the same process for scale. Each
// figure is the median of runs of 1000 ticks, the kinds taking turns.
//
//   bench_instruments [--seconds S]   (time per figure, default 1)

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "bench/bench_levels.h"
#include "scene/collision_world.h"
#include "scene/geodetic.h"
#include "scene/level.h"
#include "sensors/air_data.h"
#include "sensors/gnss.h"
#include "sensors/imu.h"
#include "sensors/range_sensor.h"

namespace {

namespace fs = std::filesystem;
using namespace sandbox;
using Clock = std::chrono::steady_clock;

constexpr int kTicks = 1000;

Eigen::Isometry3d Circle(double t) {
  const double v = 50.0, r = 500.0, w = v / r;
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translation() = Eigen::Vector3d(r * std::sin(w * t), r - r * std::cos(w * t), 1000.0);
  X.linear() = Eigen::AngleAxisd(w * t, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return X;
}

struct Case {
  const char* name;
  double pose_hz;
  sensors::ImuConfig config;
  bool geodetic;
};

}  // namespace

int main(int argc, char** argv) {
  double seconds = 1.0;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--seconds") == 0 && i + 1 < argc) {
      seconds = std::max(0.05, std::atof(argv[++i]));
    } else {
      std::fprintf(stderr, "usage: bench_instruments [--seconds S]\n");
      return 2;
    }
  }
  std::printf("%s\n", bench::Machine().c_str());
  try {
    const scene::Level sample =
        scene::LoadLevel(fs::path(SANDBOX_SOURCE_DIR) / "assets/sample/level.toml");
    const scene::CollisionWorld world(sample);
    sensors::RayCaster caster(1);
    const scene::LocalTangentPlane anchor({47.0, 8.0, 500.0});

    sensors::ImuConfig clean;
    clean.rate_hz = 1000.0;
    sensors::ImuConfig noisy = clean;
    noisy.accel = {0.002, 3e-4, 160.0};
    noisy.gyro = {3e-4, 4e-5, 8.0};
    noisy.seed = 7;
    const std::vector<Case> cases = {{"imu, poses 1 kHz", 1000.0, clean, false},
                                     {"imu, poses 1 kHz, noise", 1000.0, noisy, false},
                                     {"imu, poses 1 kHz, WGS84", 1000.0, noisy, true},
                                     {"imu, poses 100 Hz, noise", 100.0, noisy, false}};
    // One run: kTicks ticks of a case (index) or of the single ray (-1); us a tick.
    std::vector<sensors::Imu> imus;
    for (const Case& c : cases) imus.emplace_back(c.config);
    std::vector<std::int64_t> next_tick(cases.size(), 0);
    const sensors::RangeSensorConfig ray;
    std::size_t samples = 0;
    auto run = [&](int which) {
      const auto t0 = Clock::now();
      if (which < 0) {
        const Eigen::Isometry3d X(Eigen::Translation3d(20, -25, 22));
        for (int k = 0; k < kTicks; ++k) {
          const sensors::RangeReading reading = sensors::MeasureRange(ray, world, caster, {}, X);
          samples += reading.hit;
        }
      } else {
        const Case& c = cases[std::size_t(which)];
        sensors::Imu& imu = imus[std::size_t(which)];
        sensors::ImuSamples out;
        const int per_pose = int(std::lround(1000.0 / c.pose_hz));
        for (int k = 0; k < kTicks; ++k) {
          // A 1 kHz loop: a new pose every per_pose ticks.
          const std::int64_t tick = next_tick[std::size_t(which)]++;
          const std::int64_t pose = tick / per_pose;
          const std::int64_t utime = pose * std::int64_t(std::lround(1e6 / c.pose_hz));
          const Eigen::Isometry3d X = Circle(double(utime) * 1e-6);
          imu.Run({world,
                   caster,
                   {},
                   X,
                   X,
                   nullptr,
                   double(tick) * 1e-3,
                   tick,
                   utime,
                   c.geodetic ? &anchor : nullptr},
                  &out);
          samples += out.utime.size();
        }
      }
      return std::chrono::duration<double, std::micro>(Clock::now() - t0).count() / kTicks;
    };
    for (int which = -1; which < int(cases.size()); ++which) run(which);  // warm up
    std::vector<std::vector<double>> times(cases.size() + 1);
    const auto start = Clock::now();
    while (std::chrono::duration<double>(Clock::now() - start).count() <
               seconds * double(cases.size() + 1) ||
           times[0].size() < 5) {
      for (int which = -1; which < int(cases.size()); ++which) {
        times[std::size_t(which + 1)].push_back(run(which));
      }
    }
    const double ray_us = bench::Median(times[0]);
    std::printf("%-28s %12s %12s %12s\n", "instrument", "us a tick", "of 10 us", "x one ray");
    std::printf("%-28s %12.3f %12s %12s\n", "one ray (reference)", ray_us, "", "1.000x");
    for (std::size_t i = 0; i < cases.size(); ++i) {
      const double us = bench::Median(times[i + 1]);
      std::printf("%-28s %12.3f %11.3fx %11.3fx\n", cases[i].name, us, us / 10.0, us / ray_us);
    }
    // One more instrument, timed alone after the others: `step(tick)` runs one tick.
    auto time_alone = [&](const char* name, auto&& step) {
      std::int64_t tick = 0;
      std::vector<double> alone;
      const auto begin = Clock::now();
      while (std::chrono::duration<double>(Clock::now() - begin).count() < seconds ||
             alone.size() < 5) {
        const auto t0 = Clock::now();
        for (int k = 0; k < kTicks; ++k, ++tick) step(tick);
        alone.push_back(std::chrono::duration<double, std::micro>(Clock::now() - t0).count() /
                        kTicks);
      }
      const double us = bench::Median(alone);
      std::printf("%-28s %12.3f %11.3fx %11.3fx\n", name, us, us / 10.0, us / ray_us);
    };
    sensors::GnssConfig gnss_config;
    gnss_config.rate_hz = 1000.0;
    gnss_config.horizontal_sigma_m = 1.5, gnss_config.vertical_sigma_m = 3.0;
    gnss_config.velocity_sigma_m_s = 0.1;
    sensors::Gnss gnss(gnss_config);
    sensors::GnssFixes fixes;
    time_alone("gnss, poses 1 kHz, noise", [&](std::int64_t tick) {
      const Eigen::Isometry3d X = Circle(double(tick) * 1e-3);
      gnss.Run({world, caster, {}, X, X, nullptr, 0.0, tick, tick * 1000, &anchor}, &fixes);
      samples += fixes.fixes.size();
    });
    sensors::AirDataConfig air_config;
    air_config.rate_hz = 1000.0;
    air_config.static_pressure_sigma_pa = 12.0, air_config.impact_pressure_sigma_pa = 5.0;
    air_config.temperature_sigma_k = 0.5, air_config.angle_sigma_deg = 0.2;
    sensors::AirData air(air_config);
    sensors::AirDataSamples air_out;
    scene::WindSpec wind;
    wind.velocity = Eigen::Vector3d(5.0, 2.0, 0.0);
    wind.gust_sigma_m_s = 1.5;
    time_alone("air data, 1 kHz, noise, gusts", [&](std::int64_t tick) {
      const Eigen::Isometry3d X = Circle(double(tick) * 1e-3);
      air.Run({world, caster, {}, X, X, nullptr, 0.0, tick, tick * 1000, &anchor, &wind}, &air_out);
      samples += air_out.samples.size();
    });
    std::printf("(%zu samples and hits counted)\n", samples);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "bench_instruments: %s\n", error.what());
    return 1;
  }
  return 0;
}
