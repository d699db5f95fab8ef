#include "sensors/lidar_returns.h"

#include <cmath>

namespace sandbox::sensors {
namespace {

// SplitMix64's finaliser: a well-mixed 64-bit value of its argument.
std::uint64_t Mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// The standard normal quantile at p in (0, 1) (inverse transform sampling):
// Acklam's rational approximation, relative error under 1.2e-9; the tails
// (p < 0.02425 or > 0.97575, 5% of draws) take a logarithm and a square root.
double NormalQuantile(double p) {
  static constexpr double a[] = {-3.969683028665376e+01, 2.209460984245205e+02,
                                 -2.759285104469687e+02, 1.383577518672690e+02,
                                 -3.066479806614716e+01, 2.506628277459239e+00};
  static constexpr double b[] = {-5.447609879822406e+01, 1.615858368580409e+02,
                                 -1.556989798598866e+02, 6.680131188771972e+01,
                                 -1.328068155288572e+01};
  static constexpr double c[] = {-7.784894002430293e-03, -3.223964580411365e-01,
                                 -2.400758277161838e+00, -2.549732539343734e+00,
                                 4.374664141464968e+00,  2.938163982698783e+00};
  static constexpr double d[] = {7.784695709041462e-03, 3.224671290700398e-01,
                                 2.445134137142996e+00, 3.754408661907416e+00};
  constexpr double kLow = 0.02425;
  if (p < kLow || p > 1.0 - kLow) {
    const double q = std::sqrt(-2.0 * std::log(p < kLow ? p : 1.0 - p));
    const double z = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
                     ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
    return p < kLow ? z : -z;
  }
  const double q = p - 0.5, r = q * q;
  return (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
         (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1.0);
}

}  // namespace

std::uint64_t SweepKey(std::uint64_t seed, std::uint64_t sweep) { return Mix(Mix(seed) ^ sweep); }

std::uint64_t Draw(std::uint64_t sweep_key, std::uint64_t beam, std::uint64_t k) {
  return Mix(sweep_key ^ (beam << 1 | k));
}

NormalDraw::NormalDraw() {
  for (int j = 1; j < kSegments; ++j) quantile_[j] = float(NormalQuantile(double(j) / kSegments));
  for (int j = 1; j + 1 < kSegments; ++j) slope_[j] = quantile_[j + 1] - quantile_[j];
}

const NormalDraw& NormalDraw::Standard() {
  static const NormalDraw table;
  return table;
}

float NormalDraw::operator()(std::uint32_t bits) const {
  if (Outer(bits)) return float(NormalQuantile((double(bits) + 0.5) * 0x1.0p-32));
  return Inner(bits);
}

RangeNoise::RangeNoise(const LidarConfig& config) {
  const LidarConfig::Noise& noise = config.noise;
  auto at_least = [](double bound) {
    const float f = float(bound);
    return double(f) < bound ? std::nextafter(f, HUGE_VALF) : f;
  };
  min_range = at_least(noise.min_range_m);
  dimmest = at_least(noise.dropout_below_intensity);
  sigma_0 = float(noise.range_sigma_m), sigma_per_m = float(noise.range_sigma_per_m);
  range = float(config.range_m);
  step = noise.range_step_m, per_step = step > 0.0 ? 1.0 / step : 0.0;
  drop_under = std::uint64_t(std::ldexp(noise.dropout_probability, 32));
}

// The loops over a whole chunk vectorise (the tails' exact quantiles apart).
__attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default"))) void DrawBeams(
    std::uint64_t sweep_key, std::size_t begin, float* __restrict z,
    std::uint64_t* __restrict chance) {
  const NormalDraw& normal = NormalDraw::Standard();
  for (std::size_t k = 0; k < kReturnChunk; ++k) chance[k] = Draw(sweep_key, begin + k, 0);
  for (std::size_t k = 0; k < kReturnChunk; ++k) {
    z[k] = normal.Inner(std::uint32_t(chance[k] >> 32));
  }
  for (std::size_t k = 0; k < kReturnChunk; ++k) {
    const std::uint32_t high = std::uint32_t(chance[k] >> 32);
    if (NormalDraw::Outer(high)) z[k] = normal(high);
  }
}

__attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default"))) void PerturbBeams(
    const RangeNoise& noise, const float* __restrict z, const std::uint64_t* __restrict chance,
    float* __restrict range, bool* __restrict kept) {
  for (std::size_t k = 0; k < kReturnChunk; ++k) kept[k] = noise.Kept(range[k], chance[k]);
  // RangeNoise::Range, a loop for each kind of step (a choice in the loop
  // keeps it from vectorising).
  if (noise.step > 0.0) {
    for (std::size_t k = 0; k < kReturnChunk; ++k) {
      range[k] = noise.Clamped(noise.Rounded(noise.Added(range[k], z[k])));
    }
  } else {
    for (std::size_t k = 0; k < kReturnChunk; ++k) {
      range[k] = noise.Clamped(noise.Added(range[k], z[k]));
    }
  }
}

__attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default"))) void BrightnessOf(
    const RayHits& hits, const RayBatch& rays, std::size_t begin, std::size_t end,
    double reference2, float* __restrict brightness) {
  const float* reflectivity = hits.reflectivity.data();
  const Eigen::Vector3f* normal = hits.normal_W.data();
  const Eigen::Vector3f* direction = rays.direction.data();
  const float* distance = hits.distance_m.data();
  for (std::size_t q = begin; q < end; ++q) {
    brightness[q - begin] =
        Brightness(reflectivity[q], normal[q], direction[q], distance[q], reference2);
  }
}

}  // namespace sandbox::sensors
