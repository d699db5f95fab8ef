#pragma once
// A lidar's returns chunk by chunk (internal to lidar.cc): the seeded noise's
// draws and its perturbation of the ranges, and the intensity law, in loops
// that vectorise. The loops are built for x86-64-v4 (AVX-512), v3 (AVX2) and
// the baseline (target_clones) and this module without contracted
// multiply-adds, so each gives the same bits (docs/reference/sensors.md,
// "Lidar noise" and "Intensity").

#include <Eigen/Core>
#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "sensors/lidar.h"
#include "sensors/ray_caster.h"

namespace sandbox::sensors {

// Beams a chunk: the loops below take whole chunks.
constexpr std::size_t kReturnChunk = 4096;

// The key of sweep `sweep` of a lidar with `seed` (SplitMix64 of both).
std::uint64_t SweepKey(std::uint64_t seed, std::uint64_t sweep);
// Draw k (0 or 1) of beam `beam` of the sweep with that key: 64 random bits, a
// function of its arguments alone (no generator state: threads and order do
// not matter). Draw 0's top 32 bits make the first return's Gaussian and its
// low 32 the dropout by chance; draw 1's top 32 the last return's Gaussian.
std::uint64_t Draw(std::uint64_t sweep_key, std::uint64_t beam, std::uint64_t k);

// A standard normal draw from 32 random bits by the quantile at their uniform:
// the quantiles at j / 4096 tabled, linear in between (the top 12 bits pick
// the segment, the other 20 the place in it); the two outer segments, where
// the quantile bends fastest, exact (Acklam's approximation, relative error
// under 1.2e-9). Five times faster than the exact quantile.
class NormalDraw {
 public:
  static const NormalDraw& Standard();  // the one table
  float operator()(std::uint32_t bits) const;
  // Whether the bits fall in an outer segment.
  static bool Outer(std::uint32_t bits) {
    const std::uint32_t j = bits >> (32 - kBits);
    return j == 0 || j == kSegments - 1;
  }
  // The draw where the bits are not Outer (branch-free, so loops of it vectorise).
  float Inner(std::uint32_t bits) const {
    const std::uint32_t j = bits >> (32 - kBits);
    const float along = float(bits & ((1u << (32 - kBits)) - 1)) * 0x1.0p-20f;
    return quantile_[j] + along * slope_[j];
  }

 private:
  NormalDraw();
  static constexpr int kBits = 12, kSegments = 1 << kBits;
  float quantile_[kSegments + 1] = {};
  float slope_[kSegments] = {};
};

// A noisy lidar's parameters in the returns' own precision (a float compared
// with the float next above a bound compares as with the bound).
struct RangeNoise {
  explicit RangeNoise(const LidarConfig& config);
  // Range r with its Gaussian draw z added, rounded to the step, kept within
  // 0 .. range.
  float Range(float r, float z) const {
    const float noisy = Added(r, z);
    return Clamped(step > 0.0 ? Rounded(noisy) : noisy);
  }
  float Added(float r, float z) const { return r + (sigma_0 + sigma_per_m * r) * z; }
  // Adding and taking away 1.5 x 2^52 rounds a double to a whole number
  // (ties to even; exact below 2^51 steps, far finer than a float range
  // shows), branch-free so that loops of it vectorise.
  float Rounded(float r) const {
    constexpr double kWhole = 0x1.8p52;
    return float(((double(r) * per_step + kWhole) - kWhole) * step);
  }
  float Clamped(float r) const { return std::min(std::max(r, 0.f), range); }
  // Whether a return at range r (before noise) escapes the minimum range and
  // chance (draw 0 of its beam).
  bool Kept(float r, std::uint64_t chance) const {
    return (r >= min_range) & ((chance & 0xffffffffu) >= drop_under);
  }
  bool Dropped(std::uint64_t chance) const { return (chance & 0xffffffffu) < drop_under; }

  float min_range, dimmest, sigma_0, sigma_per_m, range;
  double step, per_step;
  std::uint64_t drop_under;  // low 32 bits under this: dropped by chance (all at 1: 2^32)
};

// The first draws of beams begin .. begin + kReturnChunk - 1: their first
// returns' Gaussians (z) and draws 0 (`chance`, for RangeNoise::Kept).
void DrawBeams(std::uint64_t sweep_key, std::size_t begin, float* z, std::uint64_t* chance);

// A chunk of single-ray beams' first returns with noise: `range` holds their
// hit distances and gets the noisy ranges, `kept` whether each escapes the
// minimum range and chance.
void PerturbBeams(const RangeNoise& noise, const float* z, const std::uint64_t* chance,
                  float* range, bool* kept);

// A hit's brightness ("Intensity"): its reflectivity x cos(incidence) x
// min(1, reference^2 / range^2), given its normal n and the ray's direction d
// (a range of 0 divides to infinity: 1).
inline float Brightness(float reflectivity, const Eigen::Vector3f& n, const Eigen::Vector3f& d,
                        float range_m, double reference2) {
  const double cosine = -double(n.x() * d.x() + n.y() * d.y() + n.z() * d.z());
  const double near = reference2 / (double(range_m) * double(range_m));
  const double falloff = near < 1.0 ? near : 1.0;
  return float(double(reflectivity) * (cosine > 0.0 ? cosine : 0.0) * falloff);
}

// Rays begin .. end's (at most kReturnChunk) Brightness into `brightness`.
// Rays that hit nothing get a number too, unused.
void BrightnessOf(const RayHits& hits, const RayBatch& rays, std::size_t begin, std::size_t end,
                  double reference2, float* brightness);

}  // namespace sandbox::sensors
