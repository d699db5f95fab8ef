#pragma once
// The ground scanner: the face scanner's -Z face along gravity only, as a
// 2.5D height map. Point (row r, column c) lies at
//   x = x_S - E + c * res,  y = y_S - E + r * res   (E = half extent)
// and holds the height of the first surface within `depth_m` below the
// sensor, or NaN where there is none.

#include <Eigen/Geometry>
#include <string>
#include <string_view>
#include <vector>

#include "scene/settings.h"
#include "sensors/ray_caster.h"
#include "sensors/sensor_context.h"

namespace sandbox::sensors {

struct GroundScannerConfig {
  double resolution_m{1.0};
  double half_extent_m{25.0};
  double depth_m{100.0};         // how far below the sensor to look
  bool surface_ids{true};        // publish each point's surface id (HeightMap::surface)
  bool normals{false};           // keep and publish each point's normal (HeightMap::normal_W)
  void ValidateOrThrow() const;  // throws std::invalid_argument naming the field

  // The [[robot.sensor]] table's own keys (docs/reference/levels.md); throws scene::LevelError
  // naming the key.
  static GroundScannerConfig Read(scene::SettingsReader& read);
  std::string Summary() const;  // "+-25 m at 1 m"
};

struct HeightMap {
  int n{0};
  double resolution_m{1.0};
  Eigen::Vector2d corner_W{Eigen::Vector2d::Zero()};  // x, y of row 0, column 0
  std::vector<double> height_m;                       // n * n, NaN without ground
  std::vector<std::int32_t> surface;                  // n * n: surface id; 0 without ground
  std::vector<Eigen::Vector3f> normal_W;  // n * n unit, world (GroundScannerConfig::normals)
  bool surface_ids{true};                 // published (GroundScannerConfig::surface_ids)
};

class GroundScanner {
 public:
  using Config = GroundScannerConfig;
  using Output = HeightMap;
  static constexpr std::string_view kType = "ground";  // [[robot.sensor]] type

  explicit GroundScanner(const GroundScannerConfig& config);
  // The loop's call (sensors/sensor.h): a map around the sensor's position.
  void Run(const SensorContext& at, HeightMap* map) const;
  void Scan(const scene::CollisionWorld& world, RayCaster& caster, const RayFilter& filter,
            const Eigen::Vector3d& p_WS, HeightMap* map) const;

 private:
  GroundScannerConfig config_;
  int n_;
};

}  // namespace sandbox::sensors
