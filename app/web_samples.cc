#include "app/web_samples.h"

#include <algorithm>
#include <cmath>
#include <variant>

namespace sandbox::app {
namespace {

using Samples = web::StreamState::Samples;

void Add(const Eigen::Vector3d& p_W, bool hit, std::int32_t surface,
         const Eigen::Vector3d& origin, Samples* out) {
  if (!p_W.allFinite()) return;
  const Eigen::Vector3f p = (p_W - origin).cast<float>();
  out->xyz.insert(out->xyz.end(), {p.x(), p.y(), p.z()});
  out->hit.push_back(hit ? 1 : 0);
  out->surface.push_back(surface);
}

std::size_t Stride(std::size_t count, std::size_t max_points) {
  return std::max<std::size_t>(1, (count + max_points - 1) / std::max<std::size_t>(1, max_points));
}

}  // namespace

Samples ViewSamples(const sensors::Sensor& sensor, const std::string& robot,
                    const Eigen::Vector3d& origin, std::size_t max_points) {
  Samples out;
  out.robot = robot;
  out.sensor = sensor.mounted().spec.name;
  out.type = sensor.mounted().spec.type;
  const sensors::SensorOutput& output = sensor.output();
  if (const auto* scan = std::get_if<sensors::FaceScan>(&output)) {
    std::size_t count = 0;
    for (const sensors::ScanFace& face : scan->faces) count += face.occupancy.size();
    const std::size_t stride = Stride(count, max_points);
    for (int f = 0; f < 6; ++f) {
      const sensors::ScanFace& face = scan->faces[std::size_t(f)];
      for (std::size_t k = 0; k < face.occupancy.size(); k += stride) {
        if (face.occupancy[k] == sensors::kUnvisited) continue;
        Add(scan->PointW(f, k), face.occupancy[k] == sensors::kOccupied, face.surface[k], origin,
            &out);
      }
    }
  } else if (const auto* map = std::get_if<sensors::HeightMap>(&output)) {
    const std::size_t n = std::size_t(map->n);
    const std::size_t stride = Stride(n * n, max_points);
    for (std::size_t k = 0; k < map->height_m.size(); k += stride) {
      const Eigen::Vector3d p(map->corner_W.x() + double(k % n) * map->resolution_m,
                              map->corner_W.y() + double(k / n) * map->resolution_m,
                              map->height_m[k]);
      Add(p, true, map->surface.empty() ? 0 : map->surface[k], origin, &out);
    }
  } else if (const auto* lidar = std::get_if<sensors::LidarScan>(&output)) {
    const std::size_t stride = Stride(lidar->points_W.size(), max_points);
    for (std::size_t k = 0; k < lidar->points_W.size(); k += stride) {
      Add(lidar->points_W[k], lidar->hit[k] != 0, lidar->surface.empty() ? 0 : lidar->surface[k],
          origin, &out);
    }
  } else if (const auto* range = std::get_if<sensors::RangeReading>(&output)) {
    Add(range->origin_W + range->direction_W * range->range_m, range->hit, range->surface, origin,
        &out);
  }
  return out;
}

}  // namespace sandbox::app
