// What moving the floating origin costs (scene::CollisionWorld::SetOrigin, as
// `sandbox run` does when the robot is 1 km from it): the move itself, and
// the full face scan after a move against one without, in the same process.
// Levels: the sample level (with its robots) and the generated 1M-triangle terrain.
//
//   bench_origin [--moves N]   (default 200)

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <vector>

#include "bench/bench_levels.h"
#include "scene/collision_world.h"
#include "scene/level.h"
#include "sensors/face_scanner.h"
#include "sensors/ray_caster.h"

namespace {

namespace fs = std::filesystem;
using namespace sandbox;
using Clock = std::chrono::steady_clock;

double Ms(Clock::time_point since) {
  return std::chrono::duration<double, std::milli>(Clock::now() - since).count();
}

void Run(const char* name, const fs::path& file, const Eigen::Vector3d& over, int moves) {
  const scene::Level level = scene::LoadLevel(file);
  scene::CollisionWorld world(level);
  sensors::RayCaster caster;
  sensors::FaceScannerConfig config;
  config.refresh = sensors::Refresh::kFull;
  const sensors::FaceScanner scanner(config);
  sensors::FaceScan scan = scanner.EmptyScan();
  const Eigen::Isometry3d X_WS{Eigen::Translation3d(over)};
  std::vector<double> move_ms, scan_ms, scan_after_move_ms;
  for (int i = 0; i < moves; ++i) {
    // A scan without a move, then a move (2 km away and back, alternately) and a scan.
    auto start = Clock::now();
    scanner.Scan(world, caster, {}, X_WS, i, &scan);
    scan_ms.push_back(Ms(start));
    start = Clock::now();
    world.SetOrigin(i % 2 == 0 ? Eigen::Vector3d(2000, 0, 0) : Eigen::Vector3d::Zero());
    move_ms.push_back(Ms(start));
    start = Clock::now();
    scanner.Scan(world, caster, {}, X_WS, i, &scan);
    scan_after_move_ms.push_back(Ms(start));
  }
  const double plain = bench::Median(scan_ms), after = bench::Median(scan_after_move_ms);
  std::printf("%-12s %8d %10.4f %10.4f %10.3f %10.3f %7.2fx\n", name,
              world.num_collision_objects(), bench::Median(move_ms),
              *std::max_element(move_ms.begin(), move_ms.end()), plain, after, after / plain);
}

}  // namespace

int main(int argc, char** argv) {
  int moves = 200;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--moves") == 0 && i + 1 < argc) {
      moves = std::max(1, std::atoi(argv[++i]));
    } else {
      std::fprintf(stderr, "usage: bench_origin [--moves N]\n");
      return 2;
    }
  }
  std::printf("%s\n", bench::Machine().c_str());
  std::printf("%-12s %8s %10s %10s %10s %10s %8s\n", "level", "objects", "move p50", "move max",
              "scan ms", "after move", "ratio");
  Run("sample", fs::path(SANDBOX_SOURCE_DIR) / "assets/sample/level.toml", {20, -25, 22}, moves);
  const fs::path dir = fs::temp_directory_path() / "sandbox-bench-origin";
  Run("1M-triangle", bench::WriteMillionTriangleLevel(dir), {500, 250, 8}, moves);
  fs::remove_all(dir);
  std::printf("\nmove: one SetOrigin (ms); scan: a full face scan (15,606 rays) without a move and "
              "right after one (median ms);\nratio: after a move over without\n");
  return 0;
}
