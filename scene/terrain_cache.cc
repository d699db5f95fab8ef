#include "scene/terrain_cache.h"

#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <fstream>
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

TerrainCache::TerrainCache(const TerrainSpec& spec) : dir_(spec.cache) {
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

std::optional<TerrainTile> TerrainCache::Load(const TileId& id) const {
  if (!enabled()) return std::nullopt;
  const fs::path path = FileOf(id);
  std::error_code error;
  const std::uintmax_t bytes = fs::file_size(path, error);
  if (error) return std::nullopt;
  std::ifstream file(path, std::ios::binary);
  std::string in(bytes, '\0');
  if (!file.read(in.data(), std::streamsize(bytes))) return std::nullopt;
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
    return std::nullopt;  // not whole: built again
  }
  tile.id = id;
  tile.origin_W = {numbers[0], numbers[1], numbers[2]};
  if (numbers[3] <= numbers[6]) {
    tile.bounds_W = Eigen::AlignedBox3d(Eigen::Vector3d(numbers[3], numbers[4], numbers[5]),
                                        Eigen::Vector3d(numbers[6], numbers[7], numbers[8]));
  }
  tile.texture_width = size[0], tile.texture_height = size[1];
  for (const std::uint32_t index : tile.indices) {
    if (index >= tile.positions.size()) return std::nullopt;
  }
  return tile;
}

void TerrainCache::Store(const TerrainTile& tile) {
  if (!enabled()) return;
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
