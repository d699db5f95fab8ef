#pragma once
// A small glTF 2.0 writer for generated assets: one .gltf (JSON) and one .bin
// per file, one node and one material per mesh. Meshes are given in the world
// frame (Z up, metres) and written Y-up as glTF requires: world (x, y, z) is
// stored as (x, z, -y).

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace sandbox::assets {

struct GeneratedMesh {
  std::string name;
  std::array<float, 4> base_color{0.8f, 0.8f, 0.8f, 1.0f};  // linear RGBA
  std::vector<std::array<float, 3>> positions;              // Z up, metres
  std::vector<std::array<float, 3>> normals;                // filled by ComputeNormals if empty
  std::vector<std::uint32_t> indices;                       // counter-clockwise seen from outside

  std::uint32_t AddVertex(float x, float y, float z);
  void AddTriangle(std::uint32_t a, std::uint32_t b, std::uint32_t c);
  // A planar quad a-b-c-d, counter-clockwise seen from outside.
  void AddQuad(const std::array<float, 3>& a, const std::array<float, 3>& b,
               const std::array<float, 3>& c, const std::array<float, 3>& d);
  // Area-weighted vertex normals (shared vertices are smooth).
  void ComputeNormals();
};

// Writes `file` (.gltf) and `file` with .bin beside it. Throws std::runtime_error.
void WriteGltf(const std::filesystem::path& file, const std::vector<GeneratedMesh>& meshes);

}  // namespace sandbox::assets
