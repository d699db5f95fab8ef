#include "assets/generators/gltf_writer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>
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

void GeneratedMesh::AddBox(const std::array<float, 3>& lo, const std::array<float, 3>& hi) {
  const float x0 = lo[0], y0 = lo[1], z0 = lo[2], x1 = hi[0], y1 = hi[1], z1 = hi[2];
  AddQuad({x1, y0, z0}, {x1, y1, z0}, {x1, y1, z1}, {x1, y0, z1});  // +x
  AddQuad({x0, y1, z0}, {x0, y0, z0}, {x0, y0, z1}, {x0, y1, z1});  // -x
  AddQuad({x1, y1, z0}, {x0, y1, z0}, {x0, y1, z1}, {x1, y1, z1});  // +y
  AddQuad({x0, y0, z0}, {x1, y0, z0}, {x1, y0, z1}, {x0, y0, z1});  // -y
  AddQuad({x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1});  // +z
  AddQuad({x0, y1, z0}, {x1, y1, z0}, {x1, y0, z0}, {x0, y0, z0});  // -z
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

std::array<float, 3> ToGltf(const std::array<float, 3>& p) { return {p[0], p[2], -p[1]}; }

namespace {

template <typename T>
void Append(std::string* bin, const std::vector<T>& values) {
  bin->append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
  while (bin->size() % 4 != 0) bin->push_back('\0');
}

// Accumulates buffer views and accessors over one binary buffer.
class BufferBuilder {
 public:
  template <typename T>
  int Add(const std::vector<T>& values, int target, int component_type, const char* type,
          const std::string& extra = "") {
    const std::size_t offset = bin_.size();
    Append(&bin_, values);
    const int view = views_count_++;
    views_ << (view > 0 ? "," : "") << "{\"buffer\":0,\"byteOffset\":" << offset
           << ",\"byteLength\":" << values.size() * sizeof(T);
    if (target != 0) views_ << ",\"target\":" << target;
    views_ << "}";
    const std::size_t components = sizeof(T) / ComponentSize(component_type);
    const std::size_t count = values.size() * components / TypeSize(type);
    accessors_ << (view > 0 ? "," : "") << "{\"bufferView\":" << view
               << ",\"componentType\":" << component_type << ",\"count\":" << count
               << ",\"type\":\"" << type << "\"" << extra << "}";
    return view;  // one accessor per view, same index
  }
  const std::string& bin() const { return bin_; }
  std::string views() const { return views_.str(); }
  std::string accessors() const { return accessors_.str(); }

 private:
  static std::size_t ComponentSize(int component_type) {
    return component_type == 5123 ? 2 : 4;  // unsigned short, else float / unsigned int
  }
  static std::size_t TypeSize(const std::string& type) {
    if (type == "VEC3") return 3;
    if (type == "VEC4") return 4;
    if (type == "MAT4") return 16;
    return 1;
  }
  std::string bin_;
  std::ostringstream views_, accessors_;
  int views_count_{0};
};

}  // namespace

void WriteGltfScene(const std::filesystem::path& file, const GltfScene& scene) {
  BufferBuilder buffer;
  std::ostringstream json_meshes, materials, nodes;
  for (std::size_t m = 0; m < scene.meshes.size(); ++m) {
    GeneratedMesh mesh = scene.meshes[m];
    if (mesh.normals.size() != mesh.positions.size()) mesh.ComputeNormals();
    std::array<float, 3> lo{}, hi{};
    lo.fill(std::numeric_limits<float>::max());
    hi.fill(-std::numeric_limits<float>::max());
    for (const auto& p : mesh.positions) {
      for (int j = 0; j < 3; ++j) lo[j] = std::min(lo[j], p[j]), hi[j] = std::max(hi[j], p[j]);
    }
    std::ostringstream bounds;
    bounds << ",\"min\":[" << lo[0] << "," << lo[1] << "," << lo[2] << "],\"max\":[" << hi[0] << ","
           << hi[1] << "," << hi[2] << "]";
    const int position = buffer.Add(mesh.positions, 34962, 5126, "VEC3", bounds.str());
    const int normal = buffer.Add(mesh.normals, 34962, 5126, "VEC3");
    const int indices = buffer.Add(mesh.indices, 34963, 5125, "SCALAR");
    json_meshes << (m > 0 ? "," : "") << "{\"name\":\"" << mesh.name
                << "\",\"primitives\":[{\"attributes\":{\"POSITION\":" << position
                << ",\"NORMAL\":" << normal;
    if (!mesh.joints.empty()) {
      json_meshes << ",\"JOINTS_0\":" << buffer.Add(mesh.joints, 34962, 5123, "VEC4")
                  << ",\"WEIGHTS_0\":" << buffer.Add(mesh.weights, 34962, 5126, "VEC4");
    }
    json_meshes << "},\"indices\":" << indices << ",\"material\":" << m << "}]}";
    const auto& c = mesh.base_color;
    materials << (m > 0 ? "," : "") << "{\"name\":\"" << mesh.name
              << "\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[" << c[0] << "," << c[1] << ","
              << c[2] << "," << c[3] << "],\"metallicFactor\":0,\"roughnessFactor\":0.9}"
              << (c[3] < 1.0f ? ",\"alphaMode\":\"BLEND\"" : "") << "}";
  }
  for (std::size_t n = 0; n < scene.nodes.size(); ++n) {
    const GltfNode& node = scene.nodes[n];
    const auto& t = node.translation;
    const auto& r = node.rotation_xyzw;
    nodes << (n > 0 ? "," : "") << "{\"name\":\"" << node.name << "\",\"translation\":[" << t[0]
          << "," << t[1] << "," << t[2] << "],\"rotation\":[" << r[0] << "," << r[1] << "," << r[2]
          << "," << r[3] << "]";
    if (node.mesh >= 0) nodes << ",\"mesh\":" << node.mesh;
    if (node.skinned) nodes << ",\"skin\":0";
    if (!node.children.empty()) {
      nodes << ",\"children\":[";
      for (std::size_t c = 0; c < node.children.size(); ++c) {
        nodes << (c > 0 ? "," : "") << node.children[c];
      }
      nodes << "]";
    }
    nodes << "}";
  }
  std::ostringstream skins;
  if (!scene.skin.joints.empty()) {
    const int inverse_bind = buffer.Add(scene.skin.inverse_bind, 0, 5126, "MAT4");
    skins << ",\"skins\":[{\"inverseBindMatrices\":" << inverse_bind << ",\"joints\":[";
    for (std::size_t j = 0; j < scene.skin.joints.size(); ++j) {
      skins << (j > 0 ? "," : "") << scene.skin.joints[j];
    }
    skins << "]}]";
  }
  std::ostringstream roots;
  for (std::size_t r = 0; r < scene.roots.size(); ++r)
    roots << (r > 0 ? "," : "") << scene.roots[r];

  std::filesystem::path bin_file = file;
  bin_file.replace_extension(".bin");
  std::ofstream bin_out(bin_file, std::ios::binary);
  bin_out.write(buffer.bin().data(), static_cast<std::streamsize>(buffer.bin().size()));
  std::ofstream json(file);
  json << std::setprecision(9)
       << "{\"asset\":{\"version\":\"2.0\",\"generator\":\"sandbox assets/generators\"},"
       << "\"scene\":0,\"scenes\":[{\"nodes\":[" << roots.str() << "]}],"
       << "\"nodes\":[" << nodes.str() << "],\"meshes\":[" << json_meshes.str() << "],"
       << "\"materials\":[" << materials.str() << "]" << skins.str() << ","
       << "\"buffers\":[{\"uri\":\"" << bin_file.filename().string()
       << "\",\"byteLength\":" << buffer.bin().size() << "}],"
       << "\"bufferViews\":[" << buffer.views() << "],\"accessors\":[" << buffer.accessors()
       << "]}\n";
  if (!bin_out || !json) throw std::runtime_error("WriteGltf(): cannot write " + file.string());
}

void WriteGltf(const std::filesystem::path& file, const std::vector<GeneratedMesh>& meshes) {
  GltfScene scene;
  for (const GeneratedMesh& world_mesh : meshes) {
    GeneratedMesh mesh = world_mesh;
    if (mesh.normals.size() != mesh.positions.size()) mesh.ComputeNormals();
    for (auto& p : mesh.positions) p = ToGltf(p);
    for (auto& n : mesh.normals) n = ToGltf(n);
    GltfNode node;
    node.name = mesh.name;
    node.mesh = static_cast<int>(scene.meshes.size());
    scene.roots.push_back(static_cast<int>(scene.nodes.size()));
    scene.nodes.push_back(node);
    scene.meshes.push_back(std::move(mesh));
  }
  WriteGltfScene(file, scene);
}

int GeneratorMain(int argc, char** argv,
                  const std::function<void(const std::filesystem::path&)>& write) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUT_DIR\n", argv[0]);
    return 2;
  }
  try {
    std::filesystem::create_directories(argv[1]);
    write(argv[1]);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "%s: %s\n", argv[0], error.what());
    return 1;
  }
  return 0;
}

}  // namespace sandbox::assets
