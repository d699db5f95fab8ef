#pragma once
// Dryden turbulence (MIL-F-8785C) for the air data instruments: gust
// velocities along the sensor frame's x, y and z (longitudinal, lateral,
// vertical), each with intensity sigma and scale length L, at airspeed V:
//   u: sigma sqrt(2 L / (pi V)) / (1 + T s)
//   v, w: sigma sqrt(L / (pi V)) (1 + sqrt(3) T s) / (1 + T s)^2,   T = L / V
// driven by white noise of spectral density pi, so each has variance sigma^2.
// u steps as its exact first-order (Gauss-Markov) process; v and w by their
// states' exact transition over the step with the noise held over it, which
// is exact in the limit of steps well below L / V (the gusts' time scale:
// 10 s at 533 m and 50 m/s). Seeded: a run repeats exactly.

#include <Eigen/Core>
#include <cstdint>
#include <random>

namespace sandbox::sensors {

class DrydenGusts {
 public:
  DrydenGusts(double sigma_m_s, double length_m, std::uint64_t seed);

  // Advances `dt_s` at airspeed `airspeed_m_s` (at least 1 m/s is taken) and
  // returns the gust, m/s, in the sensor frame.
  Eigen::Vector3d Step(double airspeed_m_s, double dt_s);

 private:
  double sigma_, length_;
  double u_{0.0};
  Eigen::Vector2d v_{Eigen::Vector2d::Zero()}, w_{Eigen::Vector2d::Zero()};  // x and x'
  std::mt19937_64 random_;
  std::normal_distribution<double> normal_;
};

}  // namespace sandbox::sensors
