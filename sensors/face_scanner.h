#pragma once
// The face scanner (../shared/DESIGN.md): a box of six 2.5D occupancy maps
// around the robot. Face f (0..5: +X, -X, +Y, -Y, +Z, -Z) is an n x n grid of
// rays, n = 2 * half_extent / resolution + 1, starting on the plane through
// the sensor origin perpendicular to the face axis and running along the axis
// for half_extent. Points are in world coordinates.
//
// Grid order: row r, column c of face f starts at
//   u_f * (-E + c * res) + v_f * (-E + r * res)   (E = half extent)
// in the sensor frame, with (u, v) = (+Y, +Z) for the X faces, (+X, +Z) for
// the Y faces and (+X, +Y) for the Z faces; index = r * n + c.

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "scene/settings.h"
#include "sensors/ray_caster.h"
#include "sensors/sensor_context.h"

namespace sandbox::sensors {

enum class Refresh {
  kFull,         // all six faces every scan
  kSixStage,     // face (tick mod 6) each scan
  kTwelveStage,  // half a face each scan: face (tick / 2) mod 6, lower rows then upper rows
};

enum class Alignment {
  kBody,   // the box turns with the sensor
  kWorld,  // the box keeps the world axes (only the sensor position counts)
};

// How a face scanner's faces are published (docs/reference/bridge.md): as points
// (scan_face_t, three floats a sample) or compact (scan_face_compact_t, a
// distance a grid cell, in 16-bit millimetres or float metres).
enum class FaceEncoding { kPoints, kMillimetres, kFloat };

struct FaceScannerConfig {
  double resolution_m{1.0};
  double half_extent_m{25.0};
  Refresh refresh{Refresh::kSixStage};
  Alignment alignment{Alignment::kBody};
  // The most samples (6 n^2) a scan may have: a finer or larger grid is
  // refused at load. The default admits 6 x 501 x 501 (25 m at 0.1 m).
  double sample_budget{2e6};
  // The most any scanner may be given: a run with one such scanner peaks at
  // about 0.9 GB (docs/reference/sensors.md).
  static constexpr double kMaxSampleBudget = 2e7;
  FaceEncoding encoding{FaceEncoding::kPoints};
  // What a sample says besides its distance (docs/reference/sensors.md, "What
  // a sample hit"): the surface id of what it hit (ScanFace::surface; always
  // kept, published unless off) and its normal (kept and published only when
  // on: a square root and a division a sample, and 12 bytes on the wire).
  bool surface_ids{true};
  bool normals{false};

  // Throws std::invalid_argument naming the field and its value: a resolution
  // or half extent that is not positive and finite, a half extent that is not
  // a whole number of resolutions, or more samples a scan than sample_budget.
  void ValidateOrThrow() const;
  int points_per_side() const;  // n

  // The [[robot.sensor]] table's own keys (docs/reference/levels.md); throws scene::LevelError
  // naming the key.
  static FaceScannerConfig Read(scene::SettingsReader& read);
  std::string Summary() const;  // "51x51x6 at 1 m"
};

// Occupancy of a scanned point.
enum Occupancy : std::int8_t { kUnvisited = -1, kFree = 0, kOccupied = 1 };

struct ScanFace {
  std::int64_t tick{-1};  // the tick its latest rows were scanned at; -1: never
  Eigen::Isometry3d X_WS{Eigen::Isometry3d::Identity()};  // sensor pose of that scan
  Eigen::Isometry3d X_WB{Eigen::Isometry3d::Identity()};  // the box of that scan (BoxFrame)
  std::vector<std::int8_t> occupancy;                     // n * n, Occupancy
  std::vector<float> distance_m;  // n * n: from the ray's start along the face axis; NaN unvisited
  std::vector<std::int32_t> surface;  // n * n: surface id of the hit; 0 free or unvisited
  // n * n with FaceScannerConfig::normals (else empty): the unit normal at
  // the hit facing the ray, world frame; zero free or unvisited.
  std::vector<Eigen::Vector3f> normal_W;
};

struct FaceScan {
  int n{0};
  std::array<ScanFace, 6> faces;
  // The grid and how it is to be published (the scanner's config).
  double resolution_m{1.0}, half_extent_m{25.0};
  FaceEncoding encoding{FaceEncoding::kPoints};
  bool surface_ids{true}, normals{false};

  // Sample k of face f in the world, from its distance and its box: the hit,
  // or the ray's end when free; NaN when unvisited. Computed on demand (a
  // scan keeps one distance a sample, not three doubles).
  Eigen::Vector3d PointW(int face, std::size_t k) const;
  // All of face f's samples so, in grid order.
  std::vector<Eigen::Vector3d> PointsW(int face) const;
};

// Face f's frame in the world: the box it was last scanned in.
using FaceFrames = std::array<Eigen::Isometry3d, 6>;

class FaceScanner {
 public:
  using Config = FaceScannerConfig;
  using Output = FaceScan;
  static constexpr std::string_view kType = "face";  // [[robot.sensor]] type

  // Throws std::invalid_argument for a bad config (see ValidateOrThrow).
  explicit FaceScanner(const FaceScannerConfig& config);

  const FaceScannerConfig& config() const { return config_; }

  // A scan sized for this scanner with every point unvisited.
  FaceScan EmptyScan() const;

  // The box's frame at sensor pose X_WS: at the sensor, with the sensor's
  // axes (body alignment) or the world's (world alignment). Face f's rays
  // start at u_f (-E + c res) + v_f (-E + r res) in it and run along FaceAxis(f).
  Eigen::Isometry3d BoxFrame(const Eigen::Isometry3d& X_WS) const;

  // Scans what is due at `tick` (see Refresh) from sensor pose X_WS and
  // writes it into `scan`; the rest of `scan` keeps its earlier values (a
  // scan of another grid size, or kept with normals by a scanner without,
  // or the other way round, starts again empty).
  void Scan(const scene::CollisionWorld& world, RayCaster& caster, const RayFilter& filter,
            const Eigen::Isometry3d& X_WS, std::int64_t tick, FaceScan* scan) const;

  // The loop's call (sensors/sensor.h): what is due at the context's tick,
  // into `scan` (sized on the first run).
  void Run(const SensorContext& at, FaceScan* scan) const;

  // Each face's box as last scanned; a face not scanned yet: the box at X_WS.
  FaceFrames LatestFrames(const FaceScan& scan, const Eigen::Isometry3d& X_WS) const;

  // The faces and row ranges due at `tick`.
  struct Part {
    int face;
    int row_begin;
    int row_end;
  };
  std::vector<Part> DueAt(std::int64_t tick) const;

  // Appends the rays of `part` from pose X_WS to `rays` (origin_W must be the
  // sensor position).
  void AppendRays(const Part& part, const Eigen::Isometry3d& X_WS, RayBatch* rays) const;
  // The same rays written into rays[first ...] of a batch already sized,
  // whose origin is origin_W; with starts_only, their starts alone (enough
  // for RayCaster::CastGrids, which takes directions and lengths from GridOf).
  void FillRays(const Part& part, const Eigen::Isometry3d& X_WS, const Eigen::Vector3d& origin_W,
                RayBatch* rays, std::size_t first, bool starts_only) const;
  // The grid those rays form (RayCaster::CastGrids), `first` being the index
  // of the part's first ray in the batch.
  RayGrid GridOf(const Part& part, const Eigen::Isometry3d& X_WS, std::size_t first) const;
  // The rays of every part due at `tick` from X_WS (a fresh batch at the
  // sensor position) and their grids.
  void GridRays(std::int64_t tick, const Eigen::Isometry3d& X_WS, RayBatch* rays,
                std::vector<RayGrid>* grids) const;

 private:
  FaceScannerConfig config_;
  int n_;
};

// Face axes in the sensor frame, in face order.
Eigen::Vector3d FaceAxis(int face);
// Face f's grid axes (u: columns, v: rows) in the box frame.
void FaceGridAxes(int face, Eigen::Vector3d* u, Eigen::Vector3d* v);

}  // namespace sandbox::sensors
