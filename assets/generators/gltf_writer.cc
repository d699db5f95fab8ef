#include "assets/generators/gltf_writer.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace sandbox::assets {

std::uint32_t GeneratedMesh::AddVertex(float x, float y, float z) {
  positions.push_back({x, y, z});
  return static_cast<std::uint32_t>(positions.size() - 1);
}

void GeneratedMesh::AddTriangle(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  indices.insert(indices.end(), {a, b, c});
}

void GeneratedMesh::AddQuad(const std::array<float, 3>& a, const std::array<float, 3>& b,
                            const std::array<float, 3>& c, const std::array<float, 3>& d) {
  const std::uint32_t ia = AddVertex(a[0], a[1], a[2]), ib = AddVertex(b[0], b[1], b[2]);
  const std::uint32_t ic = AddVertex(c[0], c[1], c[2]), id = AddVertex(d[0], d[1], d[2]);
  AddTriangle(ia, ib, ic);
  AddTriangle(ia, ic, id);
}

void GeneratedMesh::ComputeNormals() {
  std::vector<std::array<double, 3>> sum(positions.size(), {0.0, 0.0, 0.0});
  for (std::size_t i = 0; i + 2 < indices.size(); i += 3) {
    const auto& a = positions[indices[i]];
    const auto& b = positions[indices[i + 1]];
    const auto& c = positions[indices[i + 2]];
    const double u[3] = {double(b[0]) - a[0], double(b[1]) - a[1], double(b[2]) - a[2]};
    const double v[3] = {double(c[0]) - a[0], double(c[1]) - a[1], double(c[2]) - a[2]};
    const double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                         u[0] * v[1] - u[1] * v[0]};
    for (int k = 0; k < 3; ++k) {
      for (int j = 0; j < 3; ++j) sum[indices[i + k]][j] += n[j];
    }
  }
  normals.resize(positions.size());
  for (std::size_t v = 0; v < positions.size(); ++v) {
    const double length =
        std::sqrt(sum[v][0] * sum[v][0] + sum[v][1] * sum[v][1] + sum[v][2] * sum[v][2]);
    for (int j = 0; j < 3; ++j) {
      normals[v][j] = length > 0.0 ? static_cast<float>(sum[v][j] / length) : (j == 2 ? 1.f : 0.f);
    }
  }
}

namespace {

// World Z-up to glTF Y-up.
std::array<float, 3> ToGltf(const std::array<float, 3>& p) { return {p[0], p[2], -p[1]}; }

template <typename T>
void Append(std::string* bin, const std::vector<T>& values) {
  bin->append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
  while (bin->size() % 4 != 0) bin->push_back('\0');
}

}  // namespace

void WriteGltf(const std::filesystem::path& file, const std::vector<GeneratedMesh>& meshes) {
  std::string bin;
  std::ostringstream views, accessors, json_meshes, nodes, materials;
  int view = 0;
  auto add_view = [&](std::size_t offset, std::size_t length, int target) {
    views << (view > 0 ? "," : "") << "{\"buffer\":0,\"byteOffset\":" << offset
          << ",\"byteLength\":" << length << ",\"target\":" << target << "}";
    return view++;
  };
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    GeneratedMesh mesh = meshes[m];
    if (mesh.normals.size() != mesh.positions.size()) mesh.ComputeNormals();
    std::vector<std::array<float, 3>> positions, normals;
    std::array<float, 3> lo{}, hi{};
    lo.fill(std::numeric_limits<float>::max());
    hi.fill(-std::numeric_limits<float>::max());
    for (const auto& p : mesh.positions) {
      positions.push_back(ToGltf(p));
      for (int j = 0; j < 3; ++j) {
        lo[j] = std::min(lo[j], positions.back()[j]);
        hi[j] = std::max(hi[j], positions.back()[j]);
      }
    }
    for (const auto& n : mesh.normals) normals.push_back(ToGltf(n));

    std::size_t offset = bin.size();
    Append(&bin, positions);
    const int position_view = add_view(offset, positions.size() * 12, 34962);
    offset = bin.size();
    Append(&bin, normals);
    const int normal_view = add_view(offset, normals.size() * 12, 34962);
    offset = bin.size();
    Append(&bin, mesh.indices);
    const int index_view = add_view(offset, mesh.indices.size() * 4, 34963);

    const char* sep = m > 0 ? "," : "";
    accessors << sep << "{\"bufferView\":" << position_view
              << ",\"componentType\":5126,\"count\":" << positions.size()
              << ",\"type\":\"VEC3\",\"min\":[" << lo[0] << "," << lo[1] << "," << lo[2]
              << "],\"max\":[" << hi[0] << "," << hi[1] << "," << hi[2] << "]},"
              << "{\"bufferView\":" << normal_view
              << ",\"componentType\":5126,\"count\":" << normals.size() << ",\"type\":\"VEC3\"},"
              << "{\"bufferView\":" << index_view
              << ",\"componentType\":5125,\"count\":" << mesh.indices.size()
              << ",\"type\":\"SCALAR\"}";
    json_meshes << sep << "{\"name\":\"" << mesh.name << "\",\"primitives\":[{\"attributes\":"
                << "{\"POSITION\":" << 3 * m << ",\"NORMAL\":" << 3 * m + 1
                << "},\"indices\":" << 3 * m + 2 << ",\"material\":" << m << "}]}";
    nodes << sep << "{\"name\":\"" << mesh.name << "\",\"mesh\":" << m << "}";
    const auto& c = mesh.base_color;
    materials << sep << "{\"name\":\"" << mesh.name << "\",\"pbrMetallicRoughness\":"
              << "{\"baseColorFactor\":[" << c[0] << "," << c[1] << "," << c[2] << "," << c[3]
              << "],\"metallicFactor\":0,\"roughnessFactor\":0.9}"
              << (c[3] < 1.0f ? ",\"alphaMode\":\"BLEND\"" : "") << "}";
  }
  std::ostringstream scene_nodes;
  for (std::size_t m = 0; m < meshes.size(); ++m) scene_nodes << (m > 0 ? "," : "") << m;

  std::filesystem::path bin_file = file;
  bin_file.replace_extension(".bin");
  std::ofstream bin_out(bin_file, std::ios::binary);
  bin_out.write(bin.data(), static_cast<std::streamsize>(bin.size()));
  std::ofstream json(file);
  json << "{\"asset\":{\"version\":\"2.0\",\"generator\":\"sandbox assets/generators\"},"
       << "\"scene\":0,\"scenes\":[{\"nodes\":[" << scene_nodes.str() << "]}],"
       << "\"nodes\":[" << nodes.str() << "],\"meshes\":[" << json_meshes.str() << "],"
       << "\"materials\":[" << materials.str() << "],"
       << "\"buffers\":[{\"uri\":\"" << bin_file.filename().string()
       << "\",\"byteLength\":" << bin.size() << "}],"
       << "\"bufferViews\":[" << views.str() << "],\"accessors\":[" << accessors.str() << "]}\n";
  if (!bin_out || !json) throw std::runtime_error("WriteGltf(): cannot write " + file.string());
}

}  // namespace sandbox::assets
