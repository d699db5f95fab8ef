#include "scene/asset_import.h"

#include <assimp/GltfMaterial.h>
#include <assimp/config.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cctype>
#include <cstring>
#include <fstream>
#include <map>
#include <stdexcept>

#include "scene/assimp_read.h"
#include "scene/files.h"
#include "scene/heightmap.h"

// assimp's internal checks (ai_assert; Debian builds assimp with them on)
// call this and abort the process. Defined here, it takes the place of
// assimp's own for the whole program: the failed check becomes an exception,
// which assimp's importers and post-processing steps catch and turn into a
// failed import (ReadFile and ApplyPostProcessing return null with this text).
namespace Assimp {
void aiAssertViolation(const char* expression, const char* file, int line) {
  throw std::runtime_error(std::string("assimp's check '") + expression + "' failed (" + file +
                           ":" + std::to_string(line) + ")");
}
}  // namespace Assimp

namespace sandbox::scene {
namespace {

namespace fs = std::filesystem;

// File formats whose up axis or unit is known by convention or declaration.
enum class Format { kGltf, kCollada, kFbx, kQuake3, kTerragen, kOther };

Format FormatOf(const fs::path& file) {
  const std::string ext = LowerExtension(file);
  if (ext == ".gltf" || ext == ".glb") return Format::kGltf;
  if (ext == ".dae") return Format::kCollada;
  if (ext == ".fbx") return Format::kFbx;
  if (ext == ".pk3" || ext == ".bsp") return Format::kQuake3;
  if (ext == ".ter") return Format::kTerragen;
  return Format::kOther;
}

// What a Collada file declares in its <asset> header: <up_axis> and <unit meter>.
struct ColladaHeader {
  UpAxis up{UpAxis::kPosY};  // the Collada default
  double unit_m{1.0};
};

ColladaHeader ReadColladaHeader(const fs::path& file) {
  ColladaHeader header;
  std::ifstream in(file);
  std::string text(64 * 1024, '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<std::size_t>(in.gcount()));
  const std::size_t asset_end = text.find("</asset>");
  if (asset_end != std::string::npos) text.resize(asset_end);
  if (const std::size_t at = text.find("<up_axis>"); at != std::string::npos) {
    const char axis = text.c_str()[at + 9];
    if (axis == 'X') header.up = UpAxis::kPosX;
    if (axis == 'Z') header.up = UpAxis::kPosZ;
  }
  if (const std::size_t at = text.find("meter=\""); at != std::string::npos) {
    header.unit_m = std::strtod(text.c_str() + at + 7, nullptr);
    if (!(header.unit_m > 0.0)) header.unit_m = 1.0;
  }
  return header;
}

template <typename T>
bool Metadata(const aiScene& scene, const char* key, T* value) {
  return scene.mMetaData != nullptr && scene.mMetaData->Get(key, *value);
}

// FBX states its axes and unit (centimetres per unit) in its global settings.
void ReadFbxConvention(const aiScene& scene, UpAxis* up, double* unit_m) {
  int axis = 1;
  int sign = 1;
  if (Metadata(scene, "UpAxis", &axis) && Metadata(scene, "UpAxisSign", &sign)) {
    const UpAxis positive[] = {UpAxis::kPosX, UpAxis::kPosY, UpAxis::kPosZ};
    const UpAxis negative[] = {UpAxis::kNegX, UpAxis::kNegY, UpAxis::kNegZ};
    if (axis >= 0 && axis <= 2) *up = sign < 0 ? negative[axis] : positive[axis];
  } else {
    *up = UpAxis::kPosY;
  }
  double factor_d = 0.0;
  float factor_f = 0.0f;
  if (Metadata(scene, "UnitScaleFactor", &factor_d) && factor_d > 0.0) {
    *unit_m = 0.01 * factor_d;
  } else if (Metadata(scene, "UnitScaleFactor", &factor_f) && factor_f > 0.0f) {
    *unit_m = 0.01 * static_cast<double>(factor_f);
  } else {
    *unit_m = 0.01;
  }
}

}  // namespace

Eigen::Matrix4d ToEigen(const aiMatrix4x4& m) {
  Eigen::Matrix4d out;
  out << m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4, m.d1, m.d2, m.d3,
      m.d4;
  return out;
}

namespace {

// Drops faces whose vertex indices are out of range, and faces without any
// (a binary PLY can say 0; assimp's triangulation then fails its own check).
// A safety net: the Quake 3 faces, where assimp 5.2.5 left such indices, are
// rebuilt before this. Runs before any post-processing step reads the
// indices. Returns how many faces were dropped.
std::size_t DropFacesWithBadIndices(const aiScene& scene) {
  std::size_t dropped = 0;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    aiMesh* mesh = scene.mMeshes[m];
    unsigned kept = 0;
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      aiFace& face = mesh->mFaces[f];
      const bool good = face.mNumIndices > 0 && face.mIndices != nullptr &&
                        std::all_of(face.mIndices, face.mIndices + face.mNumIndices,
                                    [&](unsigned i) { return i < mesh->mNumVertices; });
      if (!good) {
        ++dropped;
        continue;
      }
      // Swap (not copy) so that every allocated index array is still freed.
      if (kept != f) {
        std::swap(mesh->mFaces[kept].mNumIndices, face.mNumIndices);
        std::swap(mesh->mFaces[kept].mIndices, face.mIndices);
      }
      ++kept;
    }
    if (kept == mesh->mNumFaces) continue;
    mesh->mNumFaces = kept;
    // The primitive types the importer set may name the dropped faces (the
    // triangulation step trusts them and fails its check otherwise).
    mesh->mPrimitiveTypes = 0;
    for (unsigned f = 0; f < kept; ++f) {
      const unsigned n = mesh->mFaces[f].mNumIndices;
      mesh->mPrimitiveTypes |= n == 1   ? aiPrimitiveType_POINT
                               : n == 2 ? aiPrimitiveType_LINE
                               : n == 3 ? aiPrimitiveType_TRIANGLE
                                        : aiPrimitiveType_POLYGON;
    }
  }
  return dropped;
}

// The Quake 3 importer of assimp 5.2.5 writes three vertices a triangle, in
// order, but leaves most face indices wrong (repeats, uninitialised values):
// rebuilds face f as vertices 3f, 3f + 1, 3f + 2 in every mesh laid out so.
// Returns how many meshes it rebuilt.
std::size_t RebuildQuake3Faces(const aiScene& scene) {
  std::size_t rebuilt = 0;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    aiMesh* mesh = scene.mMeshes[m];
    if (mesh->mNumVertices != 3 * mesh->mNumFaces) continue;
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) {
        delete[] face.mIndices;
        face.mIndices = new unsigned[3];
        face.mNumIndices = 3;
      }
      for (unsigned k = 0; k < 3; ++k) face.mIndices[k] = 3 * f + k;
    }
    ++rebuilt;
  }
  return rebuilt;
}

Material ConvertMaterial(const aiScene& scene, const aiMaterial& in, const fs::path& folder) {
  Material out;
  aiString name;
  if (in.Get(AI_MATKEY_NAME, name) == AI_SUCCESS) out.name = name.C_Str();
  // PBR base colour (glTF) carries its alpha; older formats give a diffuse
  // colour and a separate opacity.
  aiColor4D color;
  float opacity = 1.0f;
  if (in.Get(AI_MATKEY_BASE_COLOR, color) == AI_SUCCESS) {
    out.base_color = {color.r, color.g, color.b, color.a};
  } else if (in.Get(AI_MATKEY_COLOR_DIFFUSE, color) == AI_SUCCESS) {
    out.base_color = {color.r, color.g, color.b, 1.0f};
    if (in.Get(AI_MATKEY_OPACITY, opacity) == AI_SUCCESS) out.base_color.w() = opacity;
  }
  // Lightmaps: embedded only ("*N"); the Quake 3 importer files them under
  // texture index 1 of the lightmap type.
  for (unsigned index = 0; index < 2 && out.lightmap_texture_embedded < 0; ++index) {
    aiString lightmap;
    if (in.GetTexture(aiTextureType_LIGHTMAP, index, &lightmap) == AI_SUCCESS &&
        lightmap.C_Str()[0] == '*') {
      out.lightmap_texture_embedded = std::atoi(lightmap.C_Str() + 1);
    }
  }
  // glTF's alpha mode and metallic-roughness factors.
  aiString alpha_mode;
  if (in.Get(AI_MATKEY_GLTF_ALPHAMODE, alpha_mode) == AI_SUCCESS) {
    out.linear_color = true;  // only glTF materials have an alpha mode
    const std::string mode = alpha_mode.C_Str();
    out.alpha_mode = mode == "MASK"    ? AlphaMode::kMask
                     : mode == "BLEND" ? AlphaMode::kBlend
                                       : AlphaMode::kOpaque;
    if (out.alpha_mode == AlphaMode::kOpaque) out.base_color.w() = 1.0f;
  }
  in.Get(AI_MATKEY_GLTF_ALPHACUTOFF, out.alpha_cutoff);
  in.Get(AI_MATKEY_METALLIC_FACTOR, out.metallic);
  in.Get(AI_MATKEY_ROUGHNESS_FACTOR, out.roughness);
  // A texture: embedded ("*N" or by name) or a file beside the asset.
  auto texture_of = [&](aiTextureType type, std::string* path_out, int* embedded_out) {
    aiString texture;
    if (in.GetTexture(type, 0, &texture) != AI_SUCCESS) return false;
    const char* path = texture.C_Str();
    if (path[0] == '*') {
      *embedded_out = std::atoi(path + 1);
    } else if (scene.GetEmbeddedTexture(path) != nullptr) {
      for (unsigned t = 0; t < scene.mNumTextures; ++t) {
        if (scene.mTextures[t] == scene.GetEmbeddedTexture(path)) {
          *embedded_out = static_cast<int>(t);
        }
      }
    } else {
      *path_out = (folder / path).lexically_normal().string();
    }
    return true;
  };
  if (!texture_of(aiTextureType_BASE_COLOR, &out.base_color_texture_path,
                  &out.base_color_texture_embedded)) {
    texture_of(aiTextureType_DIFFUSE, &out.base_color_texture_path,
               &out.base_color_texture_embedded);
  }
  texture_of(aiTextureType_NORMALS, &out.normal_texture_path, &out.normal_texture_embedded);
  return out;
}

EmbeddedTexture ConvertTexture(const aiTexture& in, const fs::path& file,
                               const LoadLimits& limits) {
  if (in.mHeight > 0) {
    LoadLimits::Check(file,
                      "an embedded texture of " + std::to_string(in.mWidth) + " x " +
                          std::to_string(in.mHeight) + " pixels",
                      std::uint64_t{in.mWidth} * in.mHeight, limits.max_texture_pixels,
                      "max_texture_pixels");
  }
  EmbeddedTexture out;
  out.format_hint = in.achFormatHint;
  if (in.mHeight == 0) {
    out.width = static_cast<int>(in.mWidth);
    const auto* bytes = reinterpret_cast<const std::uint8_t*>(in.pcData);
    out.bytes.assign(bytes, bytes + in.mWidth);
  } else {
    out.width = static_cast<int>(in.mWidth);
    out.height = static_cast<int>(in.mHeight);
    out.bytes.reserve(std::size_t{in.mWidth} * in.mHeight * 4);
    for (std::size_t i = 0; i < std::size_t{in.mWidth} * in.mHeight; ++i) {
      const aiTexel& t = in.pcData[i];
      out.bytes.insert(out.bytes.end(), {t.r, t.g, t.b, t.a});
    }
  }
  return out;
}

}  // namespace

Mesh ConvertMesh(const aiMesh& in, std::size_t* non_triangles) {
  Mesh out;
  out.material = static_cast<int>(in.mMaterialIndex);
  out.positions_A.resize(in.mNumVertices);
  for (unsigned v = 0; v < in.mNumVertices; ++v) {
    out.positions_A[v] = {in.mVertices[v].x, in.mVertices[v].y, in.mVertices[v].z};
  }
  if (in.mNormals != nullptr) {
    out.normals_A.resize(in.mNumVertices);
    for (unsigned v = 0; v < in.mNumVertices; ++v) {
      out.normals_A[v] = {in.mNormals[v].x, in.mNormals[v].y, in.mNormals[v].z};
    }
  } else {
    out.normals_A.assign(in.mNumVertices, Eigen::Vector3f::UnitZ());
  }
  if (in.HasTextureCoords(0)) {
    out.uvs.resize(in.mNumVertices);
    for (unsigned v = 0; v < in.mNumVertices; ++v) {
      out.uvs[v] = {in.mTextureCoords[0][v].x, in.mTextureCoords[0][v].y};
    }
  }
  if (in.HasTextureCoords(1)) {
    out.lightmap_uvs.resize(in.mNumVertices);
    for (unsigned v = 0; v < in.mNumVertices; ++v) {
      out.lightmap_uvs[v] = {in.mTextureCoords[1][v].x, in.mTextureCoords[1][v].y};
    }
  }
  if (in.HasVertexColors(0)) {
    out.colors.resize(in.mNumVertices);
    for (unsigned v = 0; v < in.mNumVertices; ++v) {
      const aiColor4D& c = in.mColors[0][v];
      out.colors[v] = {c.r, c.g, c.b, c.a};
    }
  }
  out.indices.reserve(std::size_t{in.mNumFaces} * 3);
  for (unsigned f = 0; f < in.mNumFaces; ++f) {
    const aiFace& face = in.mFaces[f];
    if (face.mNumIndices != 3) {
      ++*non_triangles;
      continue;
    }
    out.indices.insert(out.indices.end(), face.mIndices, face.mIndices + 3);
  }
  return out;
}

namespace {

// Walks the node tree and collects every node with meshes, named by its path.
class NodeCollector {
 public:
  NodeCollector(const aiScene& scene, const Eigen::Affine3d& X_RF, ImportedAsset* asset)
      : scene_(scene), X_RF_(X_RF), asset_(asset) {}

  void Visit(const aiNode& node, const std::string& path, const Eigen::Matrix4d& G_FN) {
    if (node.mNumMeshes > 0) {
      ImportedNode out;
      out.path = UniquePath(path.empty() ? RootName(node) : path);
      out.X_RN = X_RF_ * Eigen::Affine3d(G_FN);
      for (unsigned i = 0; i < node.mNumMeshes; ++i) {
        Mesh mesh = ConvertMesh(*scene_.mMeshes[node.mMeshes[i]], &non_triangles_);
        if (!mesh.indices.empty()) out.meshes.push_back(std::move(mesh));
      }
      if (!out.meshes.empty()) asset_->nodes.push_back(std::move(out));
    }
    for (unsigned c = 0; c < node.mNumChildren; ++c) {
      const aiNode& child = *node.mChildren[c];
      std::string name = child.mName.C_Str();
      if (name.empty()) name = "node" + std::to_string(c);
      Visit(child, path.empty() ? name : path + "/" + name, G_FN * ToEigen(child.mTransformation));
    }
  }

  std::size_t non_triangles() const { return non_triangles_; }

 private:
  static std::string RootName(const aiNode& root) {
    const std::string name = root.mName.C_Str();
    return name.empty() || name.front() == '<' ? "root" : name;
  }

  // Duplicate paths get "#2", "#3", ... in traversal order, which is stable.
  std::string UniquePath(const std::string& path) {
    const int count = ++path_count_[path];
    return count == 1 ? path : path + "#" + std::to_string(count);
  }

  const aiScene& scene_;
  const Eigen::Affine3d X_RF_;
  ImportedAsset* asset_;
  std::map<std::string, int> path_count_;
  std::size_t non_triangles_{0};
};

}  // namespace

namespace {

std::uint32_t LittleEndian32(const unsigned char* p) {
  return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 |
         std::uint32_t(p[3]) << 24;
}

// A binary glTF must be what its header says: assimp allocates the lengths it
// reads there before it reads the chunks. Header: "glTF", version, total
// length; then chunks of (length, type, data), the first JSON.
void CheckGlbHeader(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  unsigned char header[12] = {};
  in.read(reinterpret_cast<char*>(header), sizeof(header));
  const std::uint64_t size = FileBytes(file);
  if (in.gcount() < 12 || std::memcmp(header, "glTF", 4) != 0) {
    throw LevelError(file.string() + ": not a binary glTF (no 12-byte 'glTF' header)");
  }
  if (LittleEndian32(header + 8) != size) {
    throw LevelError(file.string() + ": its header says " +
                     std::to_string(LittleEndian32(header + 8)) + " bytes, the file has " +
                     std::to_string(size));
  }
  // Every chunk within the file.
  std::uint64_t at = 12;
  while (at + 8 <= size) {
    unsigned char chunk[8];
    in.seekg(std::streamoff(at));
    if (!in.read(reinterpret_cast<char*>(chunk), 8)) break;
    const std::uint64_t length = LittleEndian32(chunk);
    if (at + 8 + length > size) {
      throw LevelError(file.string() + ": a chunk at byte " + std::to_string(at) + " says " +
                       std::to_string(length) + " bytes, past the end of the file");
    }
    at += 8 + length;
  }
}

}  // namespace

void TransformMesh(const Eigen::Affine3d& T, Mesh* mesh) {
  const Eigen::Matrix3f linear = T.linear().cast<float>();
  const Eigen::Vector3f translation = T.translation().cast<float>();
  const Eigen::Matrix3f normal_map = T.linear().inverse().transpose().cast<float>();
  for (Eigen::Vector3f& p : mesh->positions_A) p = linear * p + translation;
  for (Eigen::Vector3f& n : mesh->normals_A) {
    const Eigen::Vector3f mapped = normal_map * n;
    const float length = mapped.norm();
    if (length > 0.0f) n = mapped / length;
  }
  if (T.linear().determinant() < 0.0) {
    for (std::size_t i = 0; i + 2 < mesh->indices.size(); i += 3) {
      std::swap(mesh->indices[i + 1], mesh->indices[i + 2]);
    }
  }
}

AssimpScene ReadAssimpScene(Assimp::Importer& importer, const fs::path& file,
                            const AssetConversion& conversion, const LoadLimits& limits) {
  CheckReadable(file, limits);
  if (LowerExtension(file) == ".glb") CheckGlbHeader(file);
  if (!importer.IsExtensionSupported(LowerExtension(file))) {
    throw LevelError(file.string() + ": unsupported format '" + LowerExtension(file) +
                     "' (not a format assimp reads)");
  }
  // Collada: keep the file's own axes; the up axis is applied below with the rest.
  importer.SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_IGNORE_UP_DIRECTION, true);
  // No validation and no post-processing yet: faces with bad indices (Quake 3)
  // must go before any step reads them.
  const aiScene* scene = importer.ReadFile(file.string(), 0);
  if (scene == nullptr) {
    throw LevelError(file.string() + ": assimp could not read it: " + importer.GetErrorString());
  }
  AssimpScene out;
  if (FormatOf(file) == Format::kQuake3) {
    if (const std::size_t rebuilt = RebuildQuake3Faces(*scene); rebuilt > 0) {
      out.warnings.push_back(file.string() + ": rebuilt the faces of " + std::to_string(rebuilt) +
                             " meshes as consecutive vertex triples (assimp's Quake 3 importer "
                             "leaves their indices wrong)");
    }
  }
  if (const std::size_t dropped = DropFacesWithBadIndices(*scene); dropped > 0) {
    out.warnings.push_back(file.string() + ": dropped " + std::to_string(dropped) +
                           " faces with no or out-of-range vertex indices");
  }
  scene = importer.ApplyPostProcessing(aiProcess_Triangulate | aiProcess_GenSmoothNormals);
  if (scene == nullptr || scene->mRootNode == nullptr) {
    throw LevelError(file.string() + ": assimp could not process it: " + importer.GetErrorString());
  }
  out.scene = scene;

  // The file's (or format's) axes and unit, unless the caller overrides them.
  UpAxis up = UpAxis::kPosZ;
  double unit_m = 1.0;
  double applied_unit_m = 1.0;  // what assimp already applied (Collada <unit>)
  switch (FormatOf(file)) {
    case Format::kGltf:
      up = UpAxis::kPosY;
      break;
    case Format::kCollada: {
      const ColladaHeader header = ReadColladaHeader(file);
      up = header.up;
      unit_m = applied_unit_m = header.unit_m;
      break;
    }
    case Format::kFbx:
      ReadFbxConvention(*scene, &up, &unit_m);
      break;
    case Format::kQuake3:
      unit_m = 0.0254;  // Quake units are about an inch
      break;
    case Format::kTerragen:
    case Format::kOther:
      break;
  }
  out.up = conversion.up.value_or(up);
  out.unit_scale_m = conversion.unit_scale_m.value_or(unit_m);
  out.X_RF.linear() = (out.unit_scale_m / applied_unit_m) * UpAxisToWorld(out.up);

  const fs::path folder = file.parent_path();
  for (unsigned m = 0; m < scene->mNumMaterials; ++m) {
    out.materials.push_back(ConvertMaterial(*scene, *scene->mMaterials[m], folder));
  }
  for (unsigned t = 0; t < scene->mNumTextures; ++t) {
    out.textures.push_back(ConvertTexture(*scene->mTextures[t], file, limits));
  }
  return out;
}

std::string_view AssetReader(const fs::path& file) {
  return FormatOf(file) == Format::kTerragen ? "the Terragen reader" : "assimp";
}

ImportedAsset ImportAsset(const fs::path& file, const AssetConversion& conversion,
                          const LoadLimits& limits) {
  CheckReadable(file, limits);
  if (FormatOf(file) == Format::kTerragen) return ImportTerragen(file, conversion, limits);
  if (LowerExtension(file) == ".png" || LowerExtension(file) == ".pgm") {
    throw LevelError(file.string() +
                     ": a heightmap image needs a size; place it in a level manifest with "
                     "heightmap = \"...\" and size = [x, y, z]");
  }
  Assimp::Importer importer;
  AssimpScene read = ReadAssimpScene(importer, file, conversion, limits);
  ImportedAsset asset;
  asset.up = read.up;
  asset.unit_scale_m = read.unit_scale_m;
  asset.materials = std::move(read.materials);
  asset.textures = std::move(read.textures);
  asset.warnings = std::move(read.warnings);
  NodeCollector collector(*read.scene, read.X_RF, &asset);
  collector.Visit(*read.scene->mRootNode, "", ToEigen(read.scene->mRootNode->mTransformation));
  if (collector.non_triangles() > 0) {
    asset.warnings.push_back(file.string() + ": skipped " +
                             std::to_string(collector.non_triangles()) +
                             " point and line primitives");
  }
  if (asset.nodes.empty()) throw LevelError(file.string() + ": has no triangle meshes");
  return asset;
}

}  // namespace sandbox::scene
