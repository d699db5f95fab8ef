#include "scene/terrain_cache.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>

namespace sandbox::scene {
namespace {

namespace fs = std::filesystem;

constexpr char kMagic[8] = {'S', 'B', 'X', 'T', 'I', 'L', 'E', '1'};

std::uint64_t Fnv1a(const std::string& text) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (const unsigned char c : text) h = (h ^ c) * 0x100000001b3ull;
  return h;
}

// A file's identity for the fingerprint: its path, size and time.
std::string Identity(const fs::path& file) {
  std::error_code error;
  const auto size = fs::file_size(file, error);
  const auto time = fs::last_write_time(file, error).time_since_epoch().count();
  return fs::absolute(file).string() + ":" + std::to_string(error ? 0 : size) + ":" +
         std::to_string(error ? 0 : time);
}

template <typename T>
void Put(std::string* out, const std::vector<T>& values) {
  const std::uint64_t n = values.size();
  out->append(reinterpret_cast<const char*>(&n), sizeof(n));
  if (n > 0) out->append(reinterpret_cast<const char*>(values.data()), n * sizeof(T));
}

template <typename T>
bool Take(const std::string& in, std::size_t* at, std::vector<T>* values) {
  std::uint64_t n = 0;
  if (*at + sizeof(n) > in.size()) return false;
  std::memcpy(&n, in.data() + *at, sizeof(n));
  *at += sizeof(n);
  if (n > (in.size() - *at) / sizeof(T)) return false;
  values->resize(n);
  if (n > 0) std::memcpy(static_cast<void*>(values->data()), in.data() + *at, n * sizeof(T));
  *at += n * sizeof(T);
  return true;
}

}  // namespace

TerrainCache::TerrainCache(const TerrainSpec& spec) : spec_(spec), dir_(spec.cache) {
  if (dir_.empty()) return;
  std::ostringstream print;
  print.precision(17);
  print << "v1 " << spec.anchor.latitude_deg << ' ' << spec.anchor.longitude_deg << ' '
        << spec.anchor.height_m << ' ' << spec.tile_samples << ' ' << spec.coarse_factor << ' '
        << spec.texture_px;
  for (const fs::path& file : spec.elevation) print << " e " << Identity(file);
  for (const fs::path& file : spec.imagery) print << " i " << Identity(file);
  fingerprint_ = print.str();
  std::error_code error;
  fs::create_directories(dir_, error);
  if (error || !fs::is_directory(dir_)) {
    problem_ = "terrain cache " + dir_.string() + " cannot be made (" +
               (error ? error.message() : "it is no folder") +
               "); tiles are built from the rasters each time";
  }
}

fs::path TerrainCache::FileOf(const TileId& id) const {
  char name[40];
  std::snprintf(
      name, sizeof(name), "%016llx.tile",
      static_cast<unsigned long long>(Fnv1a(fingerprint_ + " " + std::to_string(id.key()))));
  return dir_ / name;
}

namespace {

// The most vertices and indices a tile of `spec` has: (s + 1)^2 samples of
// surface, two skirt vertices and six indices for each of 4 s edge cells.
std::uint64_t MaxVertices(const TerrainSpec& spec) {
  const std::uint64_t s = std::uint64_t(spec.tile_samples);
  return (s + 1) * (s + 1) + 8 * s;
}
std::uint64_t MaxIndices(const TerrainSpec& spec) {
  const std::uint64_t s = std::uint64_t(spec.tile_samples);
  return 6 * s * s;
}

bool Finite(const Eigen::Vector3f& v) { return v.allFinite(); }

}  // namespace

std::uint64_t TerrainCache::MaxFileBytes(const TerrainSpec& spec) {
  const std::uint64_t px = std::uint64_t(spec.texture_px);
  const std::uint64_t f = std::uint64_t(spec.coarse_factor);
  return sizeof(kMagic) + 7 * 8 + 8 + 9 * 8 + 2 * 4 + MaxVertices(spec) * (12 + 12 + 8) +
         (MaxIndices(spec) + 24 * std::uint64_t(spec.tile_samples) + f * f + 1) * 4 + px * px * 4 +
         64;
}

std::string TerrainCache::Problem(const TerrainTile& tile, const TerrainSpec& spec) {
  const std::size_t vertices = tile.positions.size();
  if (vertices > MaxVertices(spec)) {
    return std::to_string(vertices) + " vertices, more than a tile of " +
           std::to_string(spec.tile_samples) + " samples has";
  }
  if (tile.normals.size() != vertices) return "normals and positions differ in number";
  if (!tile.uvs.empty() && tile.uvs.size() != vertices) return "uvs and positions differ in number";
  if (tile.indices.size() % 3 || tile.skirt_indices.size() % 3)
    return "an index count is not a multiple of 3";
  if (tile.indices.size() > MaxIndices(spec)) return "more triangles than a tile has";
  for (const auto* list : {&tile.indices, &tile.skirt_indices}) {
    for (const std::uint32_t index : *list) {
      if (index >= vertices) return "an index beyond the vertices";
    }
  }
  // Positions are relative to the tile's origin: within a tile's size (and the
  // heights' physical bound) of it.
  constexpr float kReach = 1e6f;
  for (const Eigen::Vector3f& p : tile.positions) {
    if (!Finite(p) || p.cwiseAbs().maxCoeff() > kReach) return "a position not finite or far out";
  }
  for (const Eigen::Vector3f& n : tile.normals) {
    if (!Finite(n) || std::abs(n.norm() - 1.0f) > 1e-3f) return "a normal not of unit length";
  }
  for (const Eigen::Vector2f& uv : tile.uvs) {
    if (!uv.allFinite() || uv.cwiseAbs().maxCoeff() > 2.0f)
      return "a uv not finite or out of range";
  }
  if (!tile.origin_W.allFinite() || tile.origin_W.cwiseAbs().maxCoeff() > 1e8)
    return "the origin not finite or far out";
  if (!tile.bounds_W.isEmpty() &&
      (!tile.bounds_W.min().allFinite() || !tile.bounds_W.max().allFinite()))
    return "bounds not finite";
  if (tile.id.lod == 0 ? !tile.block_first.empty()
                       : !tile.block_first.empty() &&
                             tile.block_first.size() !=
                                 std::size_t(spec.coarse_factor * spec.coarse_factor + 1)) {
    return "block_first has " + std::to_string(tile.block_first.size()) + " entries";
  }
  for (std::size_t k = 0; k < tile.block_first.size(); ++k) {
    const std::uint32_t previous = k == 0 ? 0 : tile.block_first[k - 1];
    if (tile.block_first[k] < previous || tile.block_first[k] > tile.indices.size())
      return "block_first not ascending within the indices";
  }
  if (!tile.block_first.empty() && tile.block_first.back() != tile.indices.size())
    return "block_first does not end at the indices' end";
  const bool textured = tile.texture_width != 0 || tile.texture_height != 0;
  if (textured && (tile.texture_width != spec.texture_px || tile.texture_height != spec.texture_px))
    return "texture of " + std::to_string(tile.texture_width) + " x " +
           std::to_string(tile.texture_height) + " px where texture_px is " +
           std::to_string(spec.texture_px);
  const std::uint64_t pixels =
      textured ? std::uint64_t(tile.texture_width) * std::uint64_t(tile.texture_height) : 0;
  if (tile.texture_rgba.size() != 4 * pixels)
    return "texture of " + std::to_string(tile.texture_width) + " x " +
           std::to_string(tile.texture_height) + " px with " +
           std::to_string(tile.texture_rgba.size()) + " bytes of pixels";
  if (textured != !tile.uvs.empty()) return "uvs without a texture or a texture without uvs";
  return "";
}

TerrainCache::Loaded TerrainCache::Load(const TileId& id) const {
  Loaded loaded;
  if (!enabled()) return loaded;
  const fs::path path = FileOf(id);
  std::error_code error;
  if (!fs::exists(path, error)) return loaded;
  const auto damaged = [&](const std::string& why) {
    loaded.damage = path.string() + ": " + why;
    return loaded;
  };
  if (!fs::is_regular_file(path, error)) return damaged("not a regular file");
  const std::uintmax_t bytes = fs::file_size(path, error);
  if (error) return damaged(error.message());
  if (bytes > MaxFileBytes(spec_)) {
    return damaged(std::to_string(bytes) + " bytes, more than a tile of these settings takes (" +
                   std::to_string(MaxFileBytes(spec_)) + ")");
  }
  std::ifstream file(path, std::ios::binary);
  std::string in(bytes, '\0');
  if (!file.read(in.data(), std::streamsize(bytes))) return damaged("cannot be read");
  Loaded decoded = Decode(in, id, spec_);
  if (!decoded.damage.empty()) return damaged(decoded.damage);
  return decoded;
}

TerrainCache::Loaded TerrainCache::Decode(const std::string& in, const TileId& id,
                                          const TerrainSpec& spec) {
  Loaded loaded;
  const auto damaged = [&](const std::string& why) {
    loaded.damage = why;
    return loaded;
  };
  std::size_t at = sizeof(kMagic);
  TerrainTile tile;
  std::vector<std::uint64_t> key;
  std::vector<double> numbers;
  std::vector<std::int32_t> size;
  if (in.size() < at || std::memcmp(in.data(), kMagic, sizeof(kMagic)) != 0 ||
      !Take(in, &at, &key) || key.size() != 1 || key[0] != id.key() || !Take(in, &at, &numbers) ||
      numbers.size() != 9 || !Take(in, &at, &size) || size.size() != 2 ||
      !Take(in, &at, &tile.positions) || !Take(in, &at, &tile.normals) ||
      !Take(in, &at, &tile.uvs) || !Take(in, &at, &tile.indices) ||
      !Take(in, &at, &tile.skirt_indices) || !Take(in, &at, &tile.block_first) ||
      !Take(in, &at, &tile.texture_rgba) || at != in.size()) {
    return damaged("not a whole tile file");
  }
  tile.id = id;
  tile.origin_W = {numbers[0], numbers[1], numbers[2]};
  if (numbers[3] <= numbers[6]) {
    tile.bounds_W = Eigen::AlignedBox3d(Eigen::Vector3d(numbers[3], numbers[4], numbers[5]),
                                        Eigen::Vector3d(numbers[6], numbers[7], numbers[8]));
  } else if (!(numbers[3] == std::numeric_limits<double>::max() &&
               numbers[6] == std::numeric_limits<double>::lowest())) {
    // An empty box is stored as Eigen's (max, lowest); anything else reversed or NaN is damage.
    return damaged("bounds not finite");
  }
  tile.texture_width = size[0], tile.texture_height = size[1];
  if (const std::string problem = Problem(tile, spec); !problem.empty()) return damaged(problem);
  loaded.tile = std::move(tile);
  return loaded;
}

std::string TerrainCache::Encode(const TerrainTile& tile) {
  std::string out(kMagic, sizeof(kMagic));
  Put(&out, std::vector<std::uint64_t>{tile.id.key()});
  const Eigen::AlignedBox3d& b = tile.bounds_W;
  Put(&out,
      std::vector<double>{tile.origin_W.x(), tile.origin_W.y(), tile.origin_W.z(), b.min().x(),
                          b.min().y(), b.min().z(), b.max().x(), b.max().y(), b.max().z()});
  Put(&out, std::vector<std::int32_t>{tile.texture_width, tile.texture_height});
  Put(&out, tile.positions);
  Put(&out, tile.normals);
  Put(&out, tile.uvs);
  Put(&out, tile.indices);
  Put(&out, tile.skirt_indices);
  Put(&out, tile.block_first);
  Put(&out, tile.texture_rgba);
  return out;
}

void TerrainCache::Store(const TerrainTile& tile) {
  if (!enabled()) return;
  const std::string out = Encode(tile);
  // A name of this process's own: runs sharing the folder never write into one file.
  const fs::path file = FileOf(tile.id),
                 temporary = file.string() + "." + std::to_string(getpid()) + ".part";
  std::ofstream stream(temporary, std::ios::binary | std::ios::trunc);
  stream.write(out.data(), std::streamsize(out.size()));
  stream.close();
  std::error_code error;
  if (!stream) {
    problem_ = "terrain cache " + dir_.string() + " cannot be written (" + temporary.string() +
               "); tiles are built from the rasters from now on";
  } else {
    fs::rename(temporary, file, error);
    if (error) problem_ = "terrain cache " + dir_.string() + ": " + error.message();
  }
  if (!problem_.empty()) fs::remove(temporary, error);
}

}  // namespace sandbox::scene
