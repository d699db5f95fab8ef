#pragma once
// Render and collision geometry of the world, kept as plain contiguous arrays.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

namespace sandbox::scene {

// A texture stored inside an asset file (e.g. a glTF buffer image).
struct EmbeddedTexture {
  // Compressed (width > 0, height == 0): `bytes` is a whole image file in the
  // format `format_hint` names ("png", "jpg", ...). Raw (height > 0): `bytes`
  // is width * height RGBA8 texels, row by row.
  std::string format_hint;
  int width{0};
  int height{0};
  std::vector<std::uint8_t> bytes;
};

// How the renderer shades a surface beyond its colours: as the file says, as
// ground (grass, rock, snow and sand by slope and height, with detail
// textures) or as water (a reflective tint).
enum class Surface { kPlain, kTerrain, kWater };

// How a material's alpha is read (glTF alphaMode): ignored, a cut-out below
// `alpha_cutoff` (foliage), or blended.
enum class AlphaMode { kOpaque, kMask, kBlend };

// A surface description for the renderer. Colours are RGBA in [0, 1] as the file
// gives them (glTF: linear, others: display colours).
struct Material {
  std::string name;
  Eigen::Vector4f base_color{1.0f, 1.0f, 1.0f, 1.0f};
  bool linear_color{false};  // base_color is linear light (glTF); else a display (sRGB) colour
  AlphaMode alpha_mode{AlphaMode::kOpaque};  // kOpaque with base alpha < 1: blended
  float alpha_cutoff{0.5f};
  float metallic{0.0f};   // glTF metallic-roughness factors
  float roughness{1.0f};  // 1: no highlight
  Surface surface{Surface::kPlain};
  // Base colour texture: a file path (absolute, resolved against the asset's
  // folder) or an index into Level::textures; empty path and -1 when none.
  std::string base_color_texture_path;
  int base_color_texture_embedded{-1};
  // Baked lighting (Quake 3 maps): an index into Level::textures multiplying
  // the lit colour, read with Mesh::lightmap_uvs; -1 when none.
  int lightmap_texture_embedded{-1};
  // Tangent-space normal map (glTF normalTexture), like the base colour texture.
  std::string normal_texture_path;
  int normal_texture_embedded{-1};
};

// An indexed triangle mesh in its actor's frame A (metres, Z up).
// `positions_A` is tightly packed (12 bytes a vertex) so Bullet reads it in place.
struct Mesh {
  std::vector<Eigen::Vector3f> positions_A;
  std::vector<Eigen::Vector3f> normals_A;     // unit, one per vertex
  std::vector<Eigen::Vector2f> uvs;           // empty when the asset has none
  std::vector<Eigen::Vector2f> lightmap_uvs;  // the second UV set; empty when none
  std::vector<Eigen::Vector4f> colors;        // vertex colours, RGBA 0..1; empty when none
  std::vector<std::uint32_t> indices;         // three per triangle, counter-clockwise
  int material{-1};                           // index into Level::materials, -1: default

  std::size_t num_triangles() const { return indices.size() / 3; }
};

}  // namespace sandbox::scene
