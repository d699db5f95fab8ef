#include "scene/heightmap.h"

#include <png.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>

#include "scene/files.h"

namespace sandbox::scene {
namespace {

namespace fs = std::filesystem;

// The whole file, once it is known to be a regular file within the limits.
std::vector<std::uint8_t> ReadAll(const fs::path& file, const LoadLimits& limits) {
  CheckReadable(file, limits);
  std::ifstream in(file, std::ios::binary);
  if (!in) throw LevelError(file.string() + ": cannot be read");
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void CheckSamples(const fs::path& file, std::uint64_t cols, std::uint64_t rows,
                  const LoadLimits& limits) {
  LoadLimits::Check(file,
                    "a grid of " + std::to_string(cols) + " x " + std::to_string(rows) + " samples",
                    cols * rows, limits.max_heightmap_samples, "max_heightmap_samples");
}

ImportedAsset AssetFromGrid(const fs::path& file, const HeightGrid& grid) {
  ImportedAsset asset;
  ImportedNode node;
  node.path = file.stem().string();
  node.meshes.push_back(MeshFromHeightGrid(grid));
  asset.nodes.push_back(std::move(node));
  return asset;
}

// Little-endian Terragen chunks: "SIZE", "XPTS", "YPTS" (int16 + 2 pad bytes),
// "SCAL" (3 floats), "CRAD" (float), "CRVM" (uint32), "ALTW" (heightscale,
// baseheight, then the int16 grid), "EOF ".
class TerragenReader {
 public:
  TerragenReader(const fs::path& file, std::vector<std::uint8_t> bytes, const LoadLimits& limits)
      : file_(file), bytes_(std::move(bytes)), limits_(limits) {}

  HeightGrid Read() {
    if (bytes_.size() < 16 || std::memcmp(bytes_.data(), "TERRAGENTERRAIN ", 16) != 0) {
      Fail("not a Terragen terrain (no TERRAGENTERRAIN header)");
    }
    at_ = 16;
    int size = 0, xpts = 0, ypts = 0;
    Eigen::Vector3d scale_m{30.0, 30.0, 30.0};
    while (at_ + 4 <= bytes_.size()) {
      const std::string marker(reinterpret_cast<const char*>(&bytes_[at_]), 4);
      at_ += 4;
      if (marker == "SIZE") {
        size = Int16(), Skip(2);
      } else if (marker == "XPTS") {
        xpts = Int16(), Skip(2);
      } else if (marker == "YPTS") {
        ypts = Int16(), Skip(2);
      } else if (marker == "SCAL") {
        for (int i = 0; i < 3; ++i) scale_m[i] = Float();
      } else if (marker == "CRAD") {
        Skip(4);
      } else if (marker == "CRVM") {
        Skip(4);
      } else if (marker == "ALTW") {
        if (xpts == 0) xpts = size + 1;
        if (ypts == 0) ypts = xpts;
        return ReadHeights(xpts, ypts, scale_m);
      } else if (marker == "EOF ") {
        break;
      } else {
        Fail("unknown chunk '" + marker + "' at byte " + std::to_string(at_ - 4));
      }
    }
    Fail("no ALTW height chunk");
    return {};
  }

 private:
  HeightGrid ReadHeights(int xpts, int ypts, const Eigen::Vector3d& scale_m) {
    if (xpts < 2 || ypts < 2)
      Fail("grid of " + std::to_string(xpts) + " x " + std::to_string(ypts) + " points");
    CheckSamples(file_, std::uint64_t(xpts), std::uint64_t(ypts), limits_);
    const double height_scale = Int16();
    const double base_height = Int16();
    const std::size_t count = std::size_t(xpts) * std::size_t(ypts);
    if (at_ + 2 * count > bytes_.size()) Fail("height grid is cut short");
    HeightGrid grid;
    grid.cols = xpts;
    grid.rows = ypts;
    grid.spacing_m = {scale_m.x(), scale_m.y()};
    // Terragen rows run south to north; the grid's row 0 is the north edge.
    grid.origin_m = {0.0, scale_m.y() * (ypts - 1)};
    grid.height_m.resize(count);
    for (int file_row = 0; file_row < ypts; ++file_row) {
      for (int col = 0; col < xpts; ++col) {
        const double elevation = base_height + Int16() * height_scale / 65536.0;
        grid.height_m[std::size_t(ypts - 1 - file_row) * xpts + col] =
            static_cast<float>(elevation * scale_m.z());
      }
    }
    return grid;
  }

  int Int16() {
    Need(2);
    const auto value = static_cast<std::int16_t>(bytes_[at_] | (bytes_[at_ + 1] << 8));
    at_ += 2;
    return value;
  }
  double Float() {
    Need(4);
    float value;
    std::memcpy(&value, &bytes_[at_], 4);
    at_ += 4;
    return value;
  }
  void Skip(std::size_t n) { Need(n), at_ += n; }
  void Need(std::size_t n) {
    if (at_ + n > bytes_.size()) Fail("file ends inside a chunk");
  }
  [[noreturn]] void Fail(const std::string& what) const {
    throw LevelError(file_.string() + ": " + what);
  }

  fs::path file_;
  std::vector<std::uint8_t> bytes_;
  const LoadLimits& limits_;
  std::size_t at_{0};
};

// Binary PGM ("P5"), 8 or 16 bit (big-endian). Heights in [0, 1].
std::vector<float> ReadPgm(const fs::path& file, int* cols, int* rows, const LoadLimits& limits) {
  const std::vector<std::uint8_t> bytes = ReadAll(file, limits);
  std::size_t at = 0;
  auto token = [&]() {
    while (at < bytes.size() && (std::isspace(bytes[at]) || bytes[at] == '#')) {
      if (bytes[at] == '#') {
        while (at < bytes.size() && bytes[at] != '\n') ++at;
      } else {
        ++at;
      }
    }
    std::string out;
    while (at < bytes.size() && !std::isspace(bytes[at])) out += static_cast<char>(bytes[at++]);
    return out;
  };
  if (token() != "P5") throw LevelError(file.string() + ": not a binary PGM (P5) image");
  // Header numbers: at most 6 digits each (a PGM is at most 65535 wide, its
  // values at most 65535).
  auto number = [&](const char* what) {
    const std::string text = token();
    if (text.empty() || text.size() > 6 ||
        text.find_first_not_of("0123456789") != std::string::npos) {
      throw LevelError(file.string() + ": PGM header: " + what + " '" + text.substr(0, 16) +
                       "' is not a number up to 999999");
    }
    return std::stoi(text);
  };
  *cols = number("width");
  *rows = number("height");
  const int max_value = number("maximum value");
  ++at;  // the single white space before the data
  CheckSamples(file, std::uint64_t(*cols), std::uint64_t(*rows), limits);
  const int depth = max_value > 255 ? 2 : 1;
  const std::size_t count = std::size_t(*cols) * std::size_t(*rows);
  if (max_value <= 0 || max_value > 65535 || count == 0 || at + count * depth > bytes.size()) {
    throw LevelError(file.string() + ": PGM header or data is broken");
  }
  std::vector<float> values(count);
  for (std::size_t i = 0; i < count; ++i) {
    const unsigned v =
        depth == 2 ? (bytes[at + 2 * i] << 8) | bytes[at + 2 * i + 1] : bytes[at + i];
    values[i] = static_cast<float>(v) / static_cast<float>(max_value);
  }
  return values;
}

// PNG of any colour type, reduced to its first channel. Heights in [0, 1].
std::vector<float> ReadPng(const fs::path& file, int* cols, int* rows, const LoadLimits& limits) {
  CheckReadable(file, limits);
  png_image image;
  std::memset(&image, 0, sizeof(image));
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&image, file.string().c_str())) {
    throw LevelError(file.string() + ": cannot read PNG: " + image.message);
  }
  // The size its header states, before anything that size is allocated.
  try {
    CheckSamples(file, image.width, image.height, limits);
  } catch (const LevelError&) {
    png_image_free(&image);
    throw;
  }
  image.format = PNG_FORMAT_LINEAR_Y;  // 16-bit grey, linear
  std::vector<std::uint16_t> pixels(PNG_IMAGE_SIZE(image) / 2);
  if (!png_image_finish_read(&image, nullptr, pixels.data(), 0, nullptr)) {
    png_image_free(&image);
    throw LevelError(file.string() + ": cannot decode PNG: " + image.message);
  }
  *cols = static_cast<int>(image.width);
  *rows = static_cast<int>(image.height);
  std::vector<float> values(pixels.size());
  for (std::size_t i = 0; i < pixels.size(); ++i) values[i] = pixels[i] / 65535.0f;
  return values;
}

}  // namespace

Mesh MeshFromHeightGrid(const HeightGrid& grid) {
  if (grid.cols < 2 || grid.rows < 2 ||
      grid.height_m.size() != std::size_t(grid.cols) * std::size_t(grid.rows)) {
    throw LevelError("MeshFromHeightGrid(): a height grid needs at least 2 x 2 points");
  }
  const int cols = grid.cols, rows = grid.rows;
  auto height = [&](int c, int r) {
    c = std::clamp(c, 0, cols - 1), r = std::clamp(r, 0, rows - 1);
    return grid.height_m[std::size_t(r) * cols + c];
  };
  Mesh mesh;
  mesh.positions_A.reserve(std::size_t(cols) * rows);
  mesh.normals_A.reserve(std::size_t(cols) * rows);
  mesh.uvs.reserve(std::size_t(cols) * rows);
  const auto dx = static_cast<float>(grid.spacing_m.x());
  const auto dy = static_cast<float>(grid.spacing_m.y());
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      mesh.positions_A.emplace_back(static_cast<float>(grid.origin_m.x() + c * grid.spacing_m.x()),
                                    static_cast<float>(grid.origin_m.y() - r * grid.spacing_m.y()),
                                    height(c, r));
      // Central differences; y grows towards row 0.
      const float dz_dx = (height(c + 1, r) - height(c - 1, r)) /
                          (dx * static_cast<float>(std::min(c + 1, cols - 1) - std::max(c - 1, 0)));
      const float dz_dy = (height(c, r - 1) - height(c, r + 1)) /
                          (dy * static_cast<float>(std::min(r + 1, rows - 1) - std::max(r - 1, 0)));
      mesh.normals_A.push_back(Eigen::Vector3f(-dz_dx, -dz_dy, 1.0f).normalized());
      mesh.uvs.emplace_back(static_cast<float>(c) / (cols - 1),
                            1.0f - static_cast<float>(r) / (rows - 1));
    }
  }
  mesh.indices.reserve(std::size_t(cols - 1) * (rows - 1) * 6);
  for (int r = 0; r + 1 < rows; ++r) {
    for (int c = 0; c + 1 < cols; ++c) {
      const auto nw = static_cast<std::uint32_t>(r * cols + c), ne = nw + 1;
      const auto sw = nw + static_cast<std::uint32_t>(cols), se = sw + 1;
      // Seen from above (+Z), x right and y up: sw, se, ne and sw, ne, nw.
      mesh.indices.insert(mesh.indices.end(), {sw, se, ne, sw, ne, nw});
    }
  }
  return mesh;
}

ImportedAsset ImportTerragen(const fs::path& file, const AssetConversion& conversion,
                             const LoadLimits& limits) {
  HeightGrid grid = TerragenReader(file, ReadAll(file, limits), limits).Read();
  ImportedAsset asset = AssetFromGrid(file, grid);
  asset.up = conversion.up.value_or(UpAxis::kPosZ);
  asset.unit_scale_m = conversion.unit_scale_m.value_or(1.0);
  asset.nodes[0].X_RN.linear() = asset.unit_scale_m * UpAxisToWorld(asset.up);
  return asset;
}

ImportedAsset ImportHeightmapImage(const fs::path& file, const Eigen::Vector3d& size_m,
                                   const LoadLimits& limits) {
  const std::string ext = LowerExtension(file);
  int cols = 0, rows = 0;
  std::vector<float> values;
  if (ext == ".pgm") {
    values = ReadPgm(file, &cols, &rows, limits);
  } else if (ext == ".png") {
    values = ReadPng(file, &cols, &rows, limits);
  } else {
    throw LevelError(file.string() + ": a heightmap must be a .png or .pgm image");
  }
  HeightGrid grid;
  grid.cols = cols;
  grid.rows = rows;
  if (cols < 2 || rows < 2) throw LevelError(file.string() + ": heightmap is smaller than 2 x 2");
  grid.spacing_m = {size_m.x() / (cols - 1), size_m.y() / (rows - 1)};
  grid.origin_m = {-0.5 * size_m.x(), 0.5 * size_m.y()};
  grid.height_m.resize(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) {
    grid.height_m[i] = static_cast<float>(values[i] * size_m.z());
  }
  return AssetFromGrid(file, grid);
}

}  // namespace sandbox::scene
