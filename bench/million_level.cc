#include "bench/million_level.h"

#include <cmath>
#include <fstream>

#include "assets/generators/gltf_writer.h"

namespace sandbox::bench {

std::filesystem::path WriteMillionTriangleLevel(const std::filesystem::path& dir) {
  assets::GeneratedMesh mesh{"terrain", {0.4f, 0.5f, 0.3f, 1.0f}};
  const int cols = 1000, rows = 500;
  for (int r = 0; r <= rows; ++r) {
    for (int c = 0; c <= cols; ++c) {
      mesh.AddVertex(float(c), float(r), float(5.0 * std::sin(c / 40.0) * std::cos(r / 25.0)));
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
  assets::WriteGltf(dir / "million.gltf", {mesh});
  std::ofstream(dir / "million.toml") << "[[actor]]\nname = \"terrain\"\nfile = \"million.gltf\"\n";
  return dir / "million.toml";
}

}  // namespace sandbox::bench
