// What a sample carries beyond its distance, and what that costs: the face
// scanner's and the lidar's time with normals against without (surface ids
// are always written: the kernel keeps the id of the hit it found), the
// lidar's with intensity and with its seeded noise against without, call by
// call in one process, the median of each; and the bytes of a compact
// face with its id plane against without. Levels: the sample level and, where
// ../shared/assets is, its Quake 3 map (many actors: many id runs).
//
//   bench_samples [--seconds S]   (time per measurement, default 1)

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <tuple>
#include <vector>

#include "bench/bench_levels.h"
#include "bridge/face_points.h"
#include "scene/collision_world.h"
#include "scene/level.h"
#include "sensors/face_scanner.h"
#include "sensors/lidar.h"
#include "sensors/ray_caster.h"

namespace {

namespace fs = std::filesystem;
using namespace sandbox;
using Clock = std::chrono::steady_clock;

// Runs without and with in turns, call by call, for `seconds`: the median
// time of each (the machine's drift and its slow moments fall on both alike).
// Only the pairs whose name holds this (all when empty): --only.
std::string only;

template <typename Run>
void Pair(const char* level, const char* what, int threads, double seconds, Run run) {
  if (std::string(what).find(only) == std::string::npos) return;
  run(false), run(true);  // warm up
  std::vector<double> times[2];
  const auto start = Clock::now();
  while (std::chrono::duration<double>(Clock::now() - start).count() < seconds ||
         times[0].size() < 5) {
    for (const bool with : {false, true}) {
      const auto t0 = Clock::now();
      run(with);
      times[with].push_back(std::chrono::duration<double>(Clock::now() - t0).count());
    }
  }
  const double plain = bench::Median(times[0]), with = bench::Median(times[1]);
  std::printf("%-12s %-26s %2d %10.3f %10.3f %7.3fx\n", level, what, threads, 1e3 * plain,
              1e3 * with, with / plain);
  std::fflush(stdout);
}

void RunLevel(const char* name, const fs::path& file, const Eigen::Isometry3d& X_WS,
              const Eigen::Isometry3d& X_WL, double seconds) {
  const scene::Level level = scene::LoadLevel(file);
  const scene::CollisionWorld world(level);
  for (const int threads : {1, 2}) {
    sensors::RayCaster caster(threads);
    sensors::FaceScannerConfig face;
    face.refresh = sensors::Refresh::kFull;
    face.resolution_m = 0.25;
    sensors::FaceScannerConfig face_normals = face;
    face_normals.normals = true;
    const sensors::FaceScanner plain_face(face), normal_face(face_normals);
    // Each scanner its own scan, as in the loop (one scan for both would be
    // made anew at every turn).
    sensors::FaceScan plain_scan, normal_scan;
    Pair(name, "face 201^2 normals", threads, seconds, [&](bool normals) {
      (normals ? normal_face : plain_face)
          .Scan(world, caster, {}, X_WS, 0, normals ? &normal_scan : &plain_scan);
    });
    sensors::RayBatch rays;
    std::vector<sensors::RayGrid> grids;
    plain_face.GridRays(0, X_WS, &rays, &grids);
    sensors::RayHits hits;
    Pair(name, "face 201^2 normals (cast)", threads, seconds, [&](bool normals) {
      hits.with_normals = normals;
      caster.CastGrids(world, rays, grids, {}, &hits);
    });
    for (const auto& [channels, steps, label] :
         {std::tuple{16, 1024, "16x1024"}, {64, 2048, "64x2048"}}) {
      // Plain: the exact geometry with ids only.
      sensors::LidarConfig config = sensors::LidarConfig::Uniform(channels, -25, 15, steps);
      config.intensity = false;
      const sensors::Lidar plain(config);
      config.normals = true;
      const sensors::Lidar normals(config);
      config.normals = false, config.intensity = true;
      const sensors::Lidar intensity(config);
      config.noise.range_sigma_m = 0.02, config.noise.range_sigma_per_m = 0.001;
      config.noise.dropout_probability = 0.05, config.noise.dropout_below_intensity = 0.01;
      config.noise.range_step_m = 0.005, config.noise.min_range_m = 0.5;
      const sensors::Lidar noisy(config);
      sensors::LidarConfig cone = intensity.config();
      cone.divergence.rays = 4, cone.divergence.angle_rad = 0.3 * M_PI / 180.0;
      const sensors::Lidar divergent(cone);
      sensors::LidarScan sweep;
      auto compare = [&](const char* what, const sensors::Lidar& without,
                         const sensors::Lidar& with) {
        Pair(name, (std::string("lidar ") + label + what).c_str(), threads, seconds,
             [&](bool on) { (on ? with : without).Sweep(world, caster, {}, X_WL, X_WL, &sweep); });
      };
      compare(" normals", plain, normals);
      compare(" intensity", plain, intensity);
      compare(" +noise", intensity, noisy);
      compare(" +cone x4", intensity, divergent);
    }
  }
  // The compact faces' bytes, millimetres, with and without the id plane.
  sensors::RayCaster caster(2);
  for (const double resolution : {1.0, 0.25, 0.1}) {
    sensors::FaceScannerConfig config;
    config.refresh = sensors::Refresh::kFull;
    config.resolution_m = resolution;
    config.encoding = sensors::FaceEncoding::kMillimetres;
    sensors::FaceScan scan;
    sensors::FaceScanner(config).Scan(world, caster, {}, X_WS, 0, &scan);
    std::int64_t bytes[2] = {0, 0}, runs = 0;
    for (const bool ids : {false, true}) {
      scan.surface_ids = ids;
      for (int f = 0; f < 6; ++f) {
        sandbox_msgs::scan_face_compact_t message{};
        bridge::EncodeCompactFace(scan, f, &message);
        bytes[ids] += message.getEncodedSize();
        runs += message.num_runs;
      }
    }
    std::printf(
        "%-12s compact face at %4.2f m: %d samples a face, %lld bytes a scan, %lld with "
        "the id plane (%lld runs): %.3fx\n",
        name, resolution, scan.n * scan.n, static_cast<long long>(bytes[0]),
        static_cast<long long>(bytes[1]), static_cast<long long>(runs),
        double(bytes[1]) / double(bytes[0]));
  }
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = 1.0;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--seconds") == 0 && i + 1 < argc) {
      seconds = std::max(0.05, std::atof(argv[++i]));
    } else if (std::strcmp(argv[i], "--only") == 0 && i + 1 < argc) {
      only = argv[++i];
    } else {
      std::fprintf(stderr, "usage: bench_samples [--seconds S] [--only PART_OF_A_NAME]\n");
      return 2;
    }
  }
  std::printf("%s\nray kernel: %s\n", bench::Machine().c_str(), sensors::RayCaster::kernel());
  std::printf("%-12s %-26s %2s %10s %10s %8s\n", "level", "sensor, with what", "th", "without ms",
              "with ms", "ratio");
  try {
    const fs::path sample = fs::path(SANDBOX_SOURCE_DIR) / "assets/sample/level.toml";
    const Eigen::Isometry3d over_valley(Eigen::Translation3d(20, -25, 22) *
                                        Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()));
    RunLevel("sample", sample, over_valley, over_valley, seconds);
    const fs::path q3 = fs::path(SANDBOX_SHARED_ASSETS) / "q3-de4th-run1/de4th_run1.pk3";
    if (fs::exists(q3)) {
      const Eigen::Vector3d middle = scene::LoadLevel(q3).bounds_W().center();
      const Eigen::Isometry3d hall(Eigen::Translation3d(middle + Eigen::Vector3d(0, -10, -30)));
      RunLevel("quake3-map", q3, hall, hall, seconds);
    }
  } catch (const std::exception& error) {
    std::fprintf(stderr, "bench_samples: %s\n", error.what());
    return 1;
  }
  std::printf(
      "ratio: with over without (surface ids are in both). Face: the face scanner's whole scan "
      "(6 x 201 x 201 at 0.25 m), and its cast alone. Lidar: a sweep with ids only against one "
      "with normals or with intensity (reflectivity x incidence x range falloff), and with "
      "intensity against intensity plus every kind of noise (range sigma and its growth, "
      "dropout by chance and by intensity, range steps, a minimum range), and with intensity "
      "against a beam divergence of four sub-rays a beam (0.3 degrees; first and last "
      "returns). Compact face: the six "
      "faces' encoded bytes with the id plane (runs of one id) over without.\n");
  return 0;
}
