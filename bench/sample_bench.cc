// What a sample carries beyond its distance, and what that costs: the face
// scanner's and the lidar's time with normals against without (surface ids
// are always written: the kernel keeps the id of the hit it found), in turns
// in one process, the best of several rounds each; and the bytes of a compact
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

template <typename Work>
double SecondsPerCall(double seconds, Work work) {
  work();  // warm up
  int calls = 0;
  const auto start = Clock::now();
  double elapsed = 0.0;
  do {
    work();
    ++calls;
    elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  } while (elapsed < seconds);
  return elapsed / calls;
}

// Plain and with-normals runs in turns, five rounds: the best of each.
template <typename Run>
void Pair(const char* level, const char* what, int threads, double seconds, Run run) {
  double plain = 1e30, with = 1e30;
  for (int round = 0; round < 5; ++round) {
    plain = std::min(plain, SecondsPerCall(seconds / 5, [&] { run(false); }));
    with = std::min(with, SecondsPerCall(seconds / 5, [&] { run(true); }));
  }
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
    sensors::FaceScan scan;
    Pair(name, "face 6x201x201 (scanner)", threads, seconds, [&](bool normals) {
      (normals ? normal_face : plain_face).Scan(world, caster, {}, X_WS, 0, &scan);
    });
    sensors::RayBatch rays;
    std::vector<sensors::RayGrid> grids;
    plain_face.GridRays(0, X_WS, &rays, &grids);
    sensors::RayHits hits;
    Pair(name, "face 6x201x201 (cast)", threads, seconds, [&](bool normals) {
      hits.with_normals = normals;
      caster.CastGrids(world, rays, grids, {}, &hits);
    });
    for (const auto& [channels, steps, label] :
         {std::tuple{16, 1024, "lidar 16x1024 (sweep)"}, {64, 2048, "lidar 64x2048 (sweep)"}}) {
      sensors::LidarConfig config = sensors::LidarConfig::Uniform(channels, -25, 15, steps);
      const sensors::Lidar plain_lidar(config);
      config.normals = true;
      const sensors::Lidar normal_lidar(config);
      sensors::LidarScan sweep;
      Pair(name, label, threads, seconds, [&](bool normals) {
        (normals ? normal_lidar : plain_lidar).Sweep(world, caster, {}, X_WL, X_WL, &sweep);
      });
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
    } else {
      std::fprintf(stderr, "usage: bench_samples [--seconds S]\n");
      return 2;
    }
  }
  std::printf("%s\nray kernel: %s\n", bench::Machine().c_str(), sensors::RayCaster::kernel());
  std::printf("%-12s %-26s %2s %10s %10s %8s\n", "level", "sensor", "th", "plain ms", "normals ms",
              "ratio");
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
      "ratio: with normals over without (surface ids are in both). Compact face: the six "
      "faces' encoded bytes with the id plane (runs of one id) over without.\n");
  return 0;
}
