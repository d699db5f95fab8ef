#include "sensors/range_sensor.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace sandbox::sensors {

void RangeSensorConfig::ValidateOrThrow() const {
  if (!direction_S.allFinite() || std::abs(direction_S.norm() - 1.0) > 1e-6) {
    throw std::invalid_argument("direction must be a unit vector");
  }
  if (!(std::isfinite(range_m) && range_m > 0.0)) {
    throw std::invalid_argument("range_m must be positive, got " +
                                (std::ostringstream() << range_m).str());
  }
}

RangeReading MeasureRange(const RangeSensorConfig& config, const scene::CollisionWorld& world,
                          RayCaster& caster, const RayFilter& filter,
                          const Eigen::Isometry3d& X_WS) {
  config.ValidateOrThrow();
  if (!X_WS.matrix().allFinite()) throw std::invalid_argument("MeasureRange(): non-finite pose");
  RayBatch ray;
  ray.origin_W = X_WS.translation();
  ray.start = {Eigen::Vector3f::Zero()};
  ray.direction = {(X_WS.linear() * config.direction_S).cast<float>()};
  ray.length_m = {static_cast<float>(config.range_m)};
  RayHits hits;
  caster.Cast(world, ray, filter, &hits);
  RangeReading reading;
  reading.origin_W = ray.origin_W;
  reading.direction_W = X_WS.linear() * config.direction_S;
  reading.hit = hits.surface[0] != RayHits::kNoHit;
  reading.range_m = hits.distance_m[0];
  reading.point_W = ray.origin_W + double(hits.distance_m[0]) * ray.direction[0].cast<double>();
  reading.normal_W = hits.normal_W[0].cast<double>();
  reading.surface = hits.surface[0];
  return reading;
}

RangeSensorConfig RangeSensorConfig::Read(scene::SettingsReader& read) {
  RangeSensorConfig ray;
  const std::vector<double> direction = read.Numbers("direction");
  if (!direction.empty()) {
    if (direction.size() != 3) read.Fail("direction", "'direction' must be [x, y, z]");
    ray.direction_S = Eigen::Vector3d(direction[0], direction[1], direction[2]).normalized();
  }
  ray.range_m = read.Number("range_m", ray.range_m);
  return ray;
}

std::string RangeSensorConfig::Summary() const {
  std::ostringstream out;
  out << range_m << " m";
  return out.str();
}

RangeSensor::RangeSensor(const RangeSensorConfig& config) : config_(config) {
  config_.ValidateOrThrow();
}

void RangeSensor::Run(const SensorContext& at, RangeReading* reading) const {
  *reading = MeasureRange(config_, at.world, at.caster, at.filter, at.X_WS);
}

}  // namespace sandbox::sensors
