// Level loading figures: wall time and peak memory of LoadLevel + CollisionWorld
// for the sample level and a generated 1M-triangle level, each against a
// reference run in the same program: assimp's bare ReadFile of the same files.
// Every measurement runs in a fresh child process so that peak memory is its own.
//
//   bench_load [--runs N] [--keep DIR]

#include <assimp/scene.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "bench/bench_levels.h"
#include "scene/collision_world.h"
#include "scene/level.h"
#include "scene/manifest.h"

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct Figures {
  double seconds{0.0};
  double peak_mib{0.0};
  double triangles{0.0};
};

double PeakMiB() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  }
  return 0.0;
}

// Runs `work` in a child process and returns what it measured.
Figures InChild(const std::function<Figures()>& work) {
  int fds[2];
  if (pipe(fds) != 0) std::perror("pipe"), std::exit(1);
  const pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    const Figures figures = work();
    if (write(fds[1], &figures, sizeof(figures)) != sizeof(figures)) _exit(1);
    _exit(0);
  }
  close(fds[1]);
  Figures figures;
  const bool ok = read(fds[0], &figures, sizeof(figures)) == sizeof(figures);
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  if (!ok || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::fprintf(stderr, "bench_load: a measurement failed\n");
    std::exit(1);
  }
  return figures;
}

Figures LoadFull(const fs::path& level_file) {
  const auto start = Clock::now();
  const sandbox::scene::Level level = sandbox::scene::LoadLevel(level_file);
  const sandbox::scene::CollisionWorld world(level);
  return {std::chrono::duration<double>(Clock::now() - start).count(), PeakMiB(),
          double(level.num_triangles())};
}

// The reference: assimp reads every file the manifest names, nothing else.
Figures AssimpReadOnly(const fs::path& level_file) {
  const sandbox::scene::LevelManifest manifest = sandbox::scene::ParseManifest(level_file);
  const auto start = Clock::now();
  double triangles = 0;
  for (const auto& actor : manifest.actors) {
    Assimp::Importer importer;
    const aiScene* scene = importer.ReadFile(actor.file.string(), 0);
    if (scene == nullptr) std::exit(1);
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) triangles += scene->mMeshes[m]->mNumFaces;
  }
  return {std::chrono::duration<double>(Clock::now() - start).count(), PeakMiB(), triangles};
}

}  // namespace

int main(int argc, char** argv) {
  int runs = 3;
  fs::path keep;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--runs") == 0 && i + 1 < argc) {
      runs = std::max(1, std::atoi(argv[++i]));
    } else if (std::strcmp(argv[i], "--keep") == 0 && i + 1 < argc) {
      keep = argv[++i];
    } else {
      std::fprintf(stderr, "usage: bench_load [--runs N] [--keep DIR]\n");
      return 2;
    }
  }
  std::printf("%s\n", sandbox::bench::Machine().c_str());
  const fs::path dir = keep.empty() ? fs::temp_directory_path() / "sandbox-bench-load" : keep;
  std::printf("generating the 1M-triangle level in %s ...\n", dir.c_str());
  std::fflush(stdout);
  // In a child, so that this process stays small for the children it forks.
  InChild([&] {
    sandbox::bench::WriteMillionTriangleLevel(dir);
    return Figures{};
  });
  const fs::path million = dir / "million.toml";
  const fs::path sample = fs::path(SANDBOX_SOURCE_DIR) / "assets/sample/level.toml";

  std::printf("\n%-12s %10s %9s %9s %12s %11s %7s\n", "level", "triangles", "load s", "peak MiB",
              "assimp s", "assimp MiB", "ratio");
  for (const auto& [name, file] :
       {std::pair{"sample", sample}, std::pair{"1M-triangle", million}}) {
    std::vector<double> load_s, peak, ref_s, ref_peak;
    double triangles = 0;
    for (int run = 0; run < runs; ++run) {
      const Figures full = InChild([&] { return LoadFull(file); });
      const Figures ref = InChild([&] { return AssimpReadOnly(file); });
      load_s.push_back(full.seconds), peak.push_back(full.peak_mib), triangles = full.triangles;
      ref_s.push_back(ref.seconds), ref_peak.push_back(ref.peak_mib);
    }
    using sandbox::bench::Median;
    std::printf("%-12s %10.0f %9.3f %9.1f %12.3f %11.1f %6.2fx\n", name, triangles, Median(load_s),
                Median(peak), Median(ref_s), Median(ref_peak), Median(load_s) / Median(ref_s));
  }
  std::printf(
      "\nload: LoadLevel + CollisionWorld (import, conversion, BVH build), median of %d "
      "runs, each in a fresh process;\nassimp: ReadFile of the same files without "
      "post-processing; ratio = load / assimp.\n",
      runs);
  if (keep.empty()) fs::remove_all(dir);
  return 0;
}
