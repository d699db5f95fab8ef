#include "bench/bench_levels.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <thread>

#include "assets/generators/gltf_writer.h"

namespace sandbox::bench {

std::filesystem::path WriteTerrainLevel(const std::filesystem::path& dir, const std::string& name,
                                        int cols, int rows, double x0, double y0) {
  assets::GeneratedMesh mesh{"terrain", {0.4f, 0.5f, 0.3f, 1.0f}};
  for (int r = 0; r <= rows; ++r) {
    for (int c = 0; c <= cols; ++c) {
      const double x = x0 + c, y = y0 + r;
      mesh.AddVertex(float(x), float(y), float(5.0 * std::sin(x / 40.0) * std::cos(y / 25.0)));
    }
  }
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const auto a = std::uint32_t(r * (cols + 1) + c), b = a + 1;
      const auto d = a + std::uint32_t(cols + 1), e = d + 1;
      mesh.AddTriangle(a, b, e);
      mesh.AddTriangle(a, e, d);
    }
  }
  std::filesystem::create_directories(dir);
  assets::WriteGltf(dir / (name + ".gltf"), {mesh});
  std::ofstream(dir / (name + ".toml"))
      << "[[actor]]\nname = \"terrain\"\nfile = \"" << name << ".gltf\"\n";
  return dir / (name + ".toml");
}

std::filesystem::path WriteMillionTriangleLevel(const std::filesystem::path& dir) {
  return WriteTerrainLevel(dir, "million", 1000, 500);
}

double Median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

std::string Machine() {
  std::string model = "unknown CPU";
  std::ifstream cpuinfo("/proc/cpuinfo");
  for (std::string line; std::getline(cpuinfo, line);) {
    const std::size_t colon = line.find(':');
    if (line.rfind("model name", 0) != 0 || colon == std::string::npos) continue;
    const std::size_t start = line.find_first_not_of(" \t", colon + 1);
    if (start != std::string::npos) model = line.substr(start);
    break;
  }
  // The instruction sets the kernels are built for (sandbox_isa_kernel) that it runs.
  std::string sets = "sse2";
  if (__builtin_cpu_supports("fma")) sets += " fma";
  if (__builtin_cpu_supports("avx2")) sets += " avx2";
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq")) sets += " avx512";
  return "machine: " + model + ", " + std::to_string(std::thread::hardware_concurrency()) +
         " logical CPUs, " + sets;
}

}  // namespace sandbox::bench
