// Over 600 lines: the GDAL side of a terrain (opening checks, coordinate
// systems, tiles and their imagery) is one unit; its header says what it offers.
#include "scene/terrain_source.h"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_minixml.h>
#include <cpl_string.h>
#include <cpl_vsi.h>
#include <gdal.h>
#include <ogr_srs_api.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>

#include "scene/files.h"
#include "scene/level.h"

namespace sandbox::scene {
namespace {

// GDAL's own messages go to its last-error slot instead of stderr while one lives.
struct QuietGdal {
  QuietGdal() {
    static std::once_flag registered;
    std::call_once(registered, [] {
      GDALAllRegister();
      GDALSetCacheMax64(std::int64_t{64} << 20);  // its block cache (default: 5% of the memory)
    });
    CPLPushErrorHandler(CPLQuietErrorHandler);
    CPLErrorReset();
  }
  ~QuietGdal() { CPLPopErrorHandler(); }
  static std::string Last(const std::string& otherwise) {
    const char* message = CPLGetLastErrorMsg();
    return message != nullptr && *message != '\0' ? std::string(message) : otherwise;
  }
};

// Why a file GDAL would open for `file` is not a regular file, or "". A VRT
// names other files (SourceFilename, nested VRTs too): GDAL opens them itself,
// so each is checked here first, with GDAL's own XML reader. A FIFO among
// them would block the open forever.
// RegularFileProblem, and GDAL's in-memory files (/vsimem/, tests and fuzzing) as files.
std::string RasterFileProblem(const std::string& name) {
  if (name.rfind("/vsimem/", 0) == 0) {
    VSIStatBufL info;
    if (VSIStatL(name.c_str(), &info) != 0) return "no such file";
    return VSI_ISREG(info.st_mode) ? "" : "is not a regular file";
  }
  return RegularFileProblem(name);
}

std::string FileListProblem(const std::filesystem::path& file, int depth = 0) {
  if (const std::string problem = RasterFileProblem(file.string()); !problem.empty()) {
    return (depth ? "it names " + file.string() + ", which " : std::string()) + problem;
  }
  if (LowerExtension(file) != ".vrt") return "";
  if (depth > 8) return "VRTs nested more than 8 deep";
  CPLXMLNode* root = CPLParseXMLFile(file.c_str());
  if (root == nullptr) return "";  // GDAL's open says what is wrong
  std::string problem;
  std::vector<const CPLXMLNode*> stack{root};
  while (!stack.empty() && problem.empty()) {
    const CPLXMLNode* node = stack.back();
    stack.pop_back();
    for (; node != nullptr && problem.empty(); node = node->psNext) {
      if (node->eType != CXT_Element) continue;
      if (EQUAL(node->pszValue, "SourceFilename")) {
        const char* name = CPLGetXMLValue(node, nullptr, "");
        const bool relative = CPLTestBool(CPLGetXMLValue(node, "relativeToVRT", "0"));
        std::filesystem::path source = name;
        if (relative) source = file.parent_path() / source;
        if (std::string(name).rfind("/vsi", 0) == 0 ||
            std::string(name).find(':') != std::string::npos) {
          problem = "it names '" + std::string(name) + "', which is not a plain file";
        } else {
          problem = FileListProblem(source, depth + 1);
        }
      } else if (node->psChild != nullptr) {
        stack.push_back(node->psChild);
      }
    }
  }
  CPLDestroyXMLNode(root);
  return problem;
}

// A coordinate system and the transformations between it and WGS84 (x =
// longitude or easting), or why they cannot be made.
struct CrsLink {
  OGRSpatialReferenceH crs{nullptr}, wgs84{nullptr};
  OGRCoordinateTransformationH to_lonlat{nullptr}, from_lonlat{nullptr};
  std::string problem;
  CrsLink() = default;
  CrsLink(const CrsLink&) = delete;
  CrsLink& operator=(const CrsLink&) = delete;
  ~CrsLink() {
    if (to_lonlat) OCTDestroyCoordinateTransformation(to_lonlat);
    if (from_lonlat) OCTDestroyCoordinateTransformation(from_lonlat);
    if (crs) OSRDestroySpatialReference(crs);
    if (wgs84) OSRDestroySpatialReference(wgs84);
  }
};

// Why `crs` claims an EPSG code that PROJ's database gives to another kind of
// coordinate system (a GeoTIFF's geographic key holding a geocentric code), or
// "". PROJ 9.1 dereferences null making a transformation from some of them
// (docs/explanation/reliability.md): such a raster is refused before one is made.
std::string IdentityProblem(OGRSpatialReferenceH crs) {
  const auto kind = [](OGRSpatialReferenceH s) {
    return OSRIsCompound(s)     ? "compound"
           : OSRIsProjected(s)  ? "projected"
           : OSRIsGeocentric(s) ? "geocentric"
           : OSRIsGeographic(s) ? "geographic"
           : OSRIsVertical(s)   ? "vertical"
                                : "other";
  };
  const char* authority = OSRGetAuthorityName(crs, nullptr);
  const char* code = OSRGetAuthorityCode(crs, nullptr);
  if (authority == nullptr || code == nullptr || !EQUAL(authority, "EPSG")) return "";
  char* end = nullptr;
  const long number = std::strtol(code, &end, 10);
  if (end == code || *end != '\0' || number <= 0 || number > std::numeric_limits<int>::max()) {
    return std::string("its coordinate system names EPSG code '") + code + "', not a number";
  }
  OGRSpatialReferenceH known = OSRNewSpatialReference(nullptr);
  std::string problem;
  if (OSRImportFromEPSG(known, int(number)) == OGRERR_NONE &&
      std::string(kind(known)) != kind(crs)) {
    problem = std::string("its coordinate system is ") + kind(crs) +
              " but calls itself EPSG:" + code + ", which is " + kind(known) + " (" +
              OSRGetName(known) + "): a GeoTIFF key with the wrong kind of code";
  }
  OSRDestroySpatialReference(known);
  return problem;
}

// PROJ looks a transformation up in its database each time one is made, most
// of the time of opening a small raster: made once per coordinate system and
// thread (transformations are not shared between threads), up to 64 of them.
std::shared_ptr<const CrsLink> LinkFor(OGRSpatialReferenceH own) {
  char* wkt = nullptr;
  OSRExportToWkt(own, &wkt);
  const std::string key = wkt != nullptr ? wkt : "";
  CPLFree(wkt);
  thread_local std::map<std::string, std::shared_ptr<const CrsLink>> links;
  if (const auto found = links.find(key); found != links.end() && !key.empty()) {
    return found->second;
  }
  auto link = std::make_shared<CrsLink>();
  link->crs = OSRClone(own);
  link->wgs84 = OSRNewSpatialReference(nullptr);
  OSRSetWellKnownGeogCS(link->wgs84, "WGS84");
  OSRSetAxisMappingStrategy(link->crs, OAMS_TRADITIONAL_GIS_ORDER);
  OSRSetAxisMappingStrategy(link->wgs84, OAMS_TRADITIONAL_GIS_ORDER);
  link->problem = IdentityProblem(link->crs);
  if (!link->problem.empty()) {
    if (links.size() < 64 && !key.empty()) links.emplace(key, link);
    return link;
  }
  link->to_lonlat = OCTNewCoordinateTransformation(link->crs, link->wgs84);
  link->from_lonlat = OCTNewCoordinateTransformation(link->wgs84, link->crs);
  if (!link->to_lonlat || !link->from_lonlat) {
    link->problem = "its coordinate system cannot be transformed to WGS84 (" +
                    QuietGdal::Last("no transformation") + ")";
  }
  if (links.size() < 64 && !key.empty()) links.emplace(key, link);
  return link;
}

// The most one block of a raster (all bands) may take: GDAL reads whole blocks.
constexpr double kMaxBlockBytes = 256.0 * (1 << 20);

}  // namespace

struct TerrainSource::Raster {
  std::filesystem::path path;
  GDALDatasetH dataset{nullptr};
  double gt[6]{0, 1, 0, 0, 0, 1};  // sample (col, row) corner -> raster coordinates
  double inverse[6]{0, 1, 0, 0, 0, 1};
  int cols{0}, rows{0}, bands{0};
  bool has_nodata{false};
  double nodata{0.0};
  std::shared_ptr<const CrsLink> link;                                    // to and from WGS84
  OGRCoordinateTransformationH to_lonlat{nullptr}, from_lonlat{nullptr};  // link's
  Eigen::Vector2d metres_per_sample{1.0, 1.0};
  bool geographic{false};                // its x is longitude in degrees
  std::vector<double> overview_factors;  // each overview's decimation (band 1)

  ~Raster() {
    if (dataset) GDALClose(dataset);
  }

  // Raster coordinates of the centre of sample (col, row).
  Eigen::Vector2d Geo(double col, double row) const {
    return {gt[0] + (col + 0.5) * gt[1] + (row + 0.5) * gt[2],
            gt[3] + (col + 0.5) * gt[4] + (row + 0.5) * gt[5]};
  }

  // Opens `file`; "" or why it cannot serve.
  std::string Open(const std::filesystem::path& file) {
    path = file;
    if (const std::string problem = FileListProblem(file); !problem.empty()) return problem;
    dataset = GDALOpen(file.c_str(), GA_ReadOnly);
    if (dataset == nullptr) return QuietGdal::Last("GDAL cannot read it");
    // Every file the dataset reads (sidecars, a VRT's sources): regular files only.
    if (char** files = GDALGetFileList(dataset)) {
      std::string problem;
      for (char** name = files; *name != nullptr && problem.empty(); ++name) {
        if (const std::string why = RasterFileProblem(*name); !why.empty())
          problem = std::string("it reads ") + *name + ", which " + why;
      }
      CSLDestroy(files);
      if (!problem.empty()) return problem;
    }
    cols = GDALGetRasterXSize(dataset);
    rows = GDALGetRasterYSize(dataset);
    bands = GDALGetRasterCount(dataset);
    if (bands < 1 || cols < 2 || rows < 2) return "no raster of at least 2 x 2 samples in it";
    if (GDALGetGeoTransform(dataset, gt) != CE_None) {
      return "it has no georeferencing (no geotransform): a world file or GeoTIFF tags are needed";
    }
    if (!std::all_of(gt, gt + 6, [](double g) { return std::isfinite(g); })) {
      return "its geotransform is not finite (pixel size or tie point NaN or infinite)";
    }
    if (!GDALInvGeoTransform(gt, inverse)) return "its geotransform cannot be inverted";
    const OGRSpatialReferenceH own = GDALGetSpatialRef(dataset);
    if (own == nullptr) {
      return "it has no georeferencing (no coordinate system): a GeoTIFF with its CRS, or a .prj, "
             "is needed";
    }
    link = LinkFor(own);
    if (!link->problem.empty()) return link->problem;
    to_lonlat = link->to_lonlat, from_lonlat = link->from_lonlat;
    // Geographic rasters: longitudes may run past +-180 (read around the
    // antimeridian), latitudes may not pass a pole.
    geographic = OSRIsGeographic(link->crs) != 0;
    if (geographic) {
      for (const double row : {0.0, double(rows)}) {
        for (const double col : {0.0, double(cols)}) {
          const double latitude = gt[3] + col * gt[4] + row * gt[5];
          if (std::abs(latitude) > 90.0) {
            return "it reaches latitude " + std::to_string(latitude) +
                   ", beyond the pole: a geographic raster must stay within +-90";
          }
        }
      }
    }
    const GDALRasterBandH band = GDALGetRasterBand(dataset, 1);
    // GDAL reads whole blocks: a header may claim blocks of gigabytes.
    int block_x = 0, block_y = 0;
    GDALGetBlockSize(band, &block_x, &block_y);
    const double block_bytes = double(block_x) * double(block_y) * double(bands) *
                               double(GDALGetDataTypeSizeBytes(GDALGetRasterDataType(band)));
    if (!(block_bytes <= kMaxBlockBytes)) {
      return "its blocks of " + std::to_string(block_x) + " x " + std::to_string(block_y) +
             " samples take " + std::to_string(std::llround(block_bytes / (1 << 20))) +
             " MB each, over " + std::to_string(int(kMaxBlockBytes / (1 << 20))) +
             " MB (write it tiled: gdal_translate -co TILED=YES)";
    }
    for (int o = 0; o < GDALGetOverviewCount(band); ++o) {
      const GDALRasterBandH overview = GDALGetOverview(band, o);
      if (overview != nullptr && GDALGetRasterBandXSize(overview) > 0)
        overview_factors.push_back(double(cols) / GDALGetRasterBandXSize(overview));
    }
    int has = 0;
    nodata = GDALGetRasterNoDataValue(band, &has);
    has_nodata = has != 0;
    return "";
  }

  // Longitude and latitude (degrees) of raster coordinates, in place; false per failed point.
  void ToLonLat(std::vector<double>* x, std::vector<double>* y, std::vector<int>* ok) const {
    ok->assign(x->size(), 0);
    if (x->empty()) return;
    OCTTransformEx(to_lonlat, int(x->size()), x->data(), y->data(), nullptr, ok->data());
  }
};

TerrainSource::TerrainSource(const TerrainSpec& spec,
                             const std::function<void(const std::filesystem::path&)>& on_open)
    : spec_(spec), plane_(spec.anchor) {
  if (spec.tile_samples < 2 || spec.coarse_factor < 1 || spec.tile_samples % spec.coarse_factor) {
    throw LevelError("[[terrain]] '" + spec.name + "': tile_samples (" +
                     std::to_string(spec.tile_samples) +
                     ") must be at least 2 and a multiple of coarse_factor (" +
                     std::to_string(spec.coarse_factor) + ")");
  }
  const QuietGdal quiet;
  for (const std::filesystem::path& file : spec.elevation) {
    auto raster = std::make_unique<Raster>();
    if (on_open) on_open(file);
    const std::string problem = raster->Open(file);
    if (!problem.empty()) {
      problems_.push_back(file.string() + ": " + problem + "; this raster is left out");
      elevation_.push_back(nullptr);
      continue;
    }
    // The spacing in metres, from neighbouring samples at the raster's centre.
    const double c = 0.5 * raster->cols, r = 0.5 * raster->rows;
    const Eigen::Vector3d p = SampleToWorldOf(*raster, c, r),
                          px = SampleToWorldOf(*raster, c + 1, r),
                          py = SampleToWorldOf(*raster, c, r + 1);
    raster->metres_per_sample = {(px - p).norm(), (py - p).norm()};
    // Samples a millimetre to 1000 km apart, or the tiles cannot be measured.
    if (!(raster->metres_per_sample.minCoeff() >= 1e-3 &&
          raster->metres_per_sample.maxCoeff() <= 1e6)) {
      problems_.push_back(file.string() + ": its samples are " +
                          std::to_string(raster->metres_per_sample.x()) + " x " +
                          std::to_string(raster->metres_per_sample.y()) +
                          " m apart at its middle, not 1 mm to 1000 km; this raster is left out");
      elevation_.push_back(nullptr);
      continue;
    }
    elevation_.push_back(std::move(raster));
  }
  for (const std::filesystem::path& file : spec.imagery) {
    auto raster = std::make_unique<Raster>();
    if (on_open) on_open(file);
    const std::string problem = raster->Open(file);
    if (!problem.empty()) {
      problems_.push_back(file.string() + ": " + problem + "; the terrain is drawn without it");
      continue;
    }
    imagery_.push_back(std::move(raster));
  }
}

TerrainSource::~TerrainSource() = default;

int TerrainSource::num_usable() const {
  return int(std::count_if(elevation_.begin(), elevation_.end(),
                           [](const auto& raster) { return raster != nullptr; }));
}

Eigen::Vector3d TerrainSource::SampleToWorldOf(const Raster& raster, double col, double row,
                                               double height_m) const {
  const Eigen::Vector2d geo = raster.Geo(col, row);
  std::vector<double> x{geo.x()}, y{geo.y()};
  std::vector<int> ok;
  raster.ToLonLat(&x, &y, &ok);
  return plane_.ToWorld({y[0], x[0], height_m});
}

Eigen::Vector3d TerrainSource::SampleToWorld(int file, int col, int row, double height_m) const {
  const Raster* raster = elevation_.at(std::size_t(file)).get();
  if (raster == nullptr)
    throw std::invalid_argument("TerrainSource::SampleToWorld(): raster left out");
  return SampleToWorldOf(*raster, col, row, height_m);
}

Eigen::Vector2d TerrainSource::ToSample(const Raster& raster, const Eigen::Vector3d& p_W) const {
  const GeodeticPoint point = plane_.ToGeodetic(p_W);
  Eigen::Vector2d best{std::numeric_limits<double>::quiet_NaN(), 0.0};
  // A geographic raster across the antimeridian holds the point at longitude
  // +-360 too: the candidate nearest the raster's middle wins.
  const int turns = raster.geographic ? 1 : 0;
  for (int turn = -turns; turn <= turns; ++turn) {
    double x = point.longitude_deg + 360.0 * turn, y = point.latitude_deg;
    int ok = 0;
    OCTTransformEx(raster.from_lonlat, 1, &x, &y, nullptr, &ok);
    if (!ok) continue;
    const double* g = raster.inverse;
    const Eigen::Vector2d s{g[0] + x * g[1] + y * g[2] - 0.5, g[3] + x * g[4] + y * g[5] - 0.5};
    const double off = std::abs(s.x() - 0.5 * raster.cols);
    if (!std::isfinite(best.x()) || off < std::abs(best.x() - 0.5 * raster.cols)) best = s;
  }
  return best;
}

namespace {

// The pixels GDAL reads for a `w` x `h` window drawn into a `size`-pixel
// texture: from the coarsest overview still at least as fine as the texture.
double ImageryPixelsRead(const std::vector<double>& overview_factors, double w, double h,
                         int size) {
  double factor = 1.0;
  for (const double overview : overview_factors) {
    if (overview > factor && w / overview >= size && h / overview >= size) factor = overview;
  }
  return (w / factor) * (h / factor);
}

int TileSpan(const TerrainSpec& spec, int lod) {
  return spec.tile_samples * (lod == 0 ? 1 : spec.coarse_factor);
}

// Tiles along one side: each has at least one cell.
int TileCount(int samples, int span) { return (samples - 2) / span + 1; }

}  // namespace

void TerrainSource::TilesNear(const Eigen::Vector3d& p_W, int lod, double radius_m,
                              std::vector<TileId>* out) const {
  for (std::size_t f = 0; f < elevation_.size(); ++f) {
    const Raster* raster = elevation_[f].get();
    if (raster == nullptr) continue;
    const Eigen::Vector2d s = ToSample(*raster, p_W);
    if (!std::isfinite(s.x())) continue;
    const int span = TileSpan(spec_, lod);
    const double rx = radius_m / raster->metres_per_sample.x(),
                 ry = radius_m / raster->metres_per_sample.y();
    const int nx = TileCount(raster->cols, span), ny = TileCount(raster->rows, span);
    // In double, clamped to the raster before any int: radii far beyond it stay in range.
    auto clamp_tile = [](double t, int last) {
      return int(std::clamp(std::floor(t), 0.0, double(last)));
    };
    if (s.x() + rx < 0 || s.y() + ry < 0 || (s.x() - rx) / span > nx || (s.y() - ry) / span > ny)
      continue;
    const int x0 = clamp_tile((s.x() - rx) / span, nx - 1),
              x1 = clamp_tile((s.x() + rx) / span, nx - 1);
    const int y0 = clamp_tile((s.y() - ry) / span, ny - 1),
              y1 = clamp_tile((s.y() + ry) / span, ny - 1);
    for (int ty = y0; ty <= y1; ++ty) {
      for (int tx = x0; tx <= x1; ++tx) {
        const TileId id{lod, int(f), tx, ty};
        if (DistanceTo(id, p_W) <= radius_m) out->push_back(id);
      }
    }
  }
}

double TerrainSource::DistanceTo(const TileId& id, const Eigen::Vector3d& p_W) const {
  const Raster* raster = elevation_.at(std::size_t(id.file)).get();
  if (raster == nullptr) return std::numeric_limits<double>::infinity();
  const Eigen::Vector2d s = ToSample(*raster, p_W);
  if (!std::isfinite(s.x())) return std::numeric_limits<double>::infinity();
  const int span = TileSpan(spec_, id.lod);
  auto outside = [](double v, double lo, double hi) { return std::max({0.0, lo - v, v - hi}); };
  const double dx = outside(s.x(), id.tx * span, std::min((id.tx + 1) * span, raster->cols - 1));
  const double dy = outside(s.y(), id.ty * span, std::min((id.ty + 1) * span, raster->rows - 1));
  return std::hypot(dx * raster->metres_per_sample.x(), dy * raster->metres_per_sample.y());
}

bool TerrainSource::Covers(const Eigen::Vector3d& p_W) const {
  for (const auto& raster : elevation_) {
    if (raster == nullptr) continue;
    const Eigen::Vector2d s = ToSample(*raster, p_W);
    if (s.x() >= 0.0 && s.y() >= 0.0 && s.x() <= raster->cols - 1 && s.y() <= raster->rows - 1) {
      return true;
    }
  }
  return false;
}

Eigen::AlignedBox2d TerrainSource::InnerFootprint_W() const {
  Eigen::AlignedBox2d box;
  for (const auto& raster : elevation_) {
    if (raster == nullptr) continue;
    const int inset = std::min({spec_.tile_samples, raster->cols / 4, raster->rows / 4});
    const double c0 = inset, c1 = raster->cols - 1 - inset, r0 = inset,
                 r1 = raster->rows - 1 - inset;
    const Eigen::Vector3d nw = SampleToWorldOf(*raster, c0, r0),
                          ne = SampleToWorldOf(*raster, c1, r0),
                          sw = SampleToWorldOf(*raster, c0, r1),
                          se = SampleToWorldOf(*raster, c1, r1);
    // The box inside the four corners.
    const Eigen::AlignedBox2d inner(
        Eigen::Vector2d(std::max(nw.x(), sw.x()), std::max(sw.y(), se.y())),
        Eigen::Vector2d(std::min(ne.x(), se.x()), std::min(nw.y(), ne.y())));
    box.extend(inner);
  }
  return box;
}

Eigen::AlignedBox3d TerrainSource::Bounds_W() const {
  const QuietGdal quiet;
  Eigen::AlignedBox3d box;
  for (const auto& raster : elevation_) {
    if (raster == nullptr) continue;
    double range[2] = {0.0, 0.0};
    if (GDALComputeRasterMinMax(GDALGetRasterBand(raster->dataset, 1), TRUE, range) != CE_None ||
        !std::isfinite(range[0]) || !std::isfinite(range[1])) {
      continue;  // no valid sample: nothing of it stands
    }
    range[0] = std::max(range[0], -kMaxHeightAboveEllipsoid_m);
    range[1] = std::min(range[1], kMaxHeightAboveEllipsoid_m);
    // A grid of points over the raster at both heights: the curvature's
    // lowest point is at a corner, its highest inside.
    constexpr int kSteps = 16;
    for (int i = 0; i <= kSteps; ++i) {
      for (int j = 0; j <= kSteps; ++j) {
        const double col = -0.5 + raster->cols * double(i) / kSteps;
        const double row = -0.5 + raster->rows * double(j) / kSteps;
        for (const double height : range) {
          const Eigen::Vector3d p = SampleToWorldOf(*raster, col, row, height);
          if (p.allFinite()) box.extend(p);
        }
      }
    }
  }
  return box;
}

double TerrainSource::fine_tile_m() const {
  for (const auto& raster : elevation_) {
    if (raster != nullptr) return raster->metres_per_sample.maxCoeff() * spec_.tile_samples;
  }
  return 0.0;
}

void TerrainSource::CheckBudgets() const {
  const LoadLimits& limits = spec_.limits;
  const std::filesystem::path& file = spec_.elevation.front();
  const std::uint64_t s = std::uint64_t(spec_.tile_samples);
  LoadLimits::Check(file,
                    "tile_samples " + std::to_string(s) + " makes tiles of " +
                        std::to_string((s + 1) * (s + 1)) + " samples",
                    (s + 1) * (s + 1), limits.max_tile_samples, "max_tile_samples");
  // A tile's memory: vertices (position, normal, uv), indices, the collision
  // shape's 32 bytes a triangle, the texture; drawn tiles again in the renderer.
  const double vertex_bytes = double((s + 1) * (s + 1) + 8 * s) * 32.0;
  const double index_bytes = 6.0 * double(s * s + 4 * s) * 4.0;
  const double texture_bytes =
      imagery_.empty() ? 0.0 : 4.0 * double(spec_.texture_px) * double(spec_.texture_px);
  const double drawn = 2.0 * (vertex_bytes + index_bytes + texture_bytes);
  const double collision = 2.0 * double(s * s) * 32.0;
  double tiles = 0.0, bytes = 0.0, fine_window_px = 0.0;
  for (const auto& raster : elevation_) {
    if (raster == nullptr) continue;
    const double side_m = raster->metres_per_sample.minCoeff() * double(s);
    // Tiles whose squares meet a circle of radius r: at most (2 r / side + 2)^2,
    // and no more than the raster has.
    auto near = [&](double radius_m, double tile_m, int span) {
      const double across = 2.0 * radius_m / tile_m + 2.0;
      const double have = double(TileCount(raster->cols, span)) * TileCount(raster->rows, span);
      return std::min(across * across, have);
    };
    const double fine = near(spec_.collision_radius_m, side_m, int(s));
    const double coarse =
        near(spec_.view_radius_m, side_m * spec_.coarse_factor, int(s) * spec_.coarse_factor);
    tiles += fine + coarse;
    bytes += fine * (drawn + collision) + coarse * drawn;
    for (const auto& image : imagery_) {
      // The image's pixels over a fine tile, from its spacing at its middle.
      const double c = 0.5 * image->cols, r = 0.5 * image->rows;
      const Eigen::Vector3d p = SampleToWorldOf(*image, c, r),
                            px = SampleToWorldOf(*image, c + 1, r),
                            py = SampleToWorldOf(*image, c, r + 1);
      const double w = std::min(double(image->cols), side_m / (px - p).norm()),
                   h = std::min(double(image->rows), side_m / (py - p).norm());
      if (std::isfinite(w) && std::isfinite(h))
        fine_window_px = std::max(
            fine_window_px, ImageryPixelsRead(image->overview_factors, w, h, spec_.texture_px));
    }
  }
  // Estimates that are not finite (a raster's extreme geometry) count as over any limit.
  const auto bounded = [](double x) { return std::isfinite(x) ? std::min(x, 1e18) : 1e18; };
  tiles = bounded(tiles), bytes = bounded(bytes), fine_window_px = bounded(fine_window_px);
  LoadLimits::Check(file,
                    "about " + std::to_string(std::llround(tiles)) +
                        " tiles near a robot at once (collision_radius_m and view_radius_m over "
                        "tiles of tile_samples)",
                    std::uint64_t(std::min(tiles, 1e18)), limits.max_terrain_tiles,
                    "max_terrain_tiles");
  const double mb = bytes / double(1 << 20);
  LoadLimits::Check(
      file,
      "about " + std::to_string(std::llround(std::min(mb, 1e18))) +
          " MB of tiles near a robot at once (tile_samples, texture_px and the radii)",
      std::uint64_t(std::min(mb, 1e18)), limits.max_terrain_mb, "max_terrain_mb");
  if (!imagery_.empty()) {
    LoadLimits::Check(spec_.imagery.front(),
                      "a fine tile's texture reads a window of about " +
                          std::to_string(std::llround(std::min(fine_window_px, 1e18))) +
                          " px (add overviews with gdaladdo, or fewer tile_samples)",
                      std::uint64_t(std::min(fine_window_px, 1e18)), limits.max_imagery_window_px,
                      "max_imagery_window_px");
  }
}

std::vector<int> TerrainSource::SampleSpan(int first, int last, int step) const {
  std::vector<int> span;
  for (int i = first; i <= last; i += step) span.push_back(i);
  if (span.back() != last) span.push_back(last);
  return span;
}

TerrainTile TerrainSource::Build(const TileId& id) const {
  const auto start = std::chrono::steady_clock::now();
  const Raster* raster = elevation_.at(std::size_t(id.file)).get();
  if (raster == nullptr) throw std::runtime_error("TerrainSource::Build(): raster left out");
  const QuietGdal quiet;
  TerrainTile tile;
  tile.id = id;
  const int span = TileSpan(spec_, id.lod), step = id.lod == 0 ? 1 : spec_.coarse_factor;
  const int c0 = id.tx * span, c1 = std::min(c0 + span, raster->cols - 1);
  const int r0 = id.ty * span, r1 = std::min(r0 + span, raster->rows - 1);
  if (c1 <= c0 || r1 <= r0) return tile;
  const int w = c1 - c0 + 1, h = r1 - r0 + 1;
  std::vector<float> heights(std::size_t(w) * std::size_t(h));
  if (GDALRasterIO(GDALGetRasterBand(raster->dataset, 1), GF_Read, c0, r0, w, h, heights.data(), w,
                   h, GDT_Float32, 0, 0) != CE_None) {
    throw std::runtime_error(raster->path.string() + ": cannot read samples " + std::to_string(c0) +
                             ".." + std::to_string(c1) + " x " + std::to_string(r0) + ".." +
                             std::to_string(r1) + " (" + QuietGdal::Last("read error") + ")");
  }
  const std::vector<int> cols = SampleSpan(c0, c1, step), rows = SampleSpan(r0, r1, step);
  const int nx = int(cols.size()), ny = int(rows.size());
  const std::size_t n = std::size_t(nx) * std::size_t(ny);
  // Raster coordinates -> longitude, latitude -> the world, in double.
  std::vector<double> x(n), y(n);
  std::vector<float> height(n);
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const std::size_t v = std::size_t(j) * std::size_t(nx) + std::size_t(i);
      const Eigen::Vector2d geo = raster->Geo(cols[std::size_t(i)], rows[std::size_t(j)]);
      x[v] = geo.x(), y[v] = geo.y();
      height[v] = heights[std::size_t(rows[std::size_t(j)] - r0) * std::size_t(w) +
                          std::size_t(cols[std::size_t(i)] - c0)];
    }
  }
  std::vector<int> ok;
  raster->ToLonLat(&x, &y, &ok);
  std::vector<Eigen::Vector3d> p_W(n);
  std::vector<char> valid(n);
  int valid_count = 0;
  Eigen::AlignedBox3d valid_W;
  for (std::size_t v = 0; v < n; ++v) {
    const bool nodata = raster->has_nodata && double(height[v]) == raster->nodata;
    const bool physical = std::abs(double(height[v])) <= kMaxHeightAboveEllipsoid_m;
    if (!nodata && std::isfinite(height[v]) && !physical) ++tile.heights_out_of_bound;
    valid[v] = ok[v] && std::isfinite(height[v]) && !nodata && physical;
    p_W[v] = plane_.ToWorld({y[v], x[v], valid[v] ? double(height[v]) : 0.0});
    if (valid[v]) valid_W.extend(p_W[v]), ++valid_count;
  }
  if (valid_count == 0) return tile;
  // The middle of the valid samples, in whole metres: no one sample moves it far.
  tile.origin_W = valid_W.center().array().round().matrix();
  tile.positions.resize(n);
  tile.normals.resize(n);
  for (std::size_t v = 0; v < n; ++v) {
    tile.positions[v] = (p_W[v] - tile.origin_W).cast<float>();
    if (valid[v]) tile.bounds_W.extend(p_W[v]);
  }
  auto at = [nx](int i, int j) { return std::size_t(j) * std::size_t(nx) + std::size_t(i); };
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const Eigen::Vector3d east =
          p_W[at(std::min(i + 1, nx - 1), j)] - p_W[at(std::max(i - 1, 0), j)];
      const Eigen::Vector3d north =
          p_W[at(i, std::max(j - 1, 0))] - p_W[at(i, std::min(j + 1, ny - 1))];
      Eigen::Vector3d normal = east.cross(north);
      if (normal.z() < 0.0) normal = -normal;
      tile.normals[at(i, j)] = normal.normalized().cast<float>();
    }
  }
  // Two triangles a cell, counter-clockwise from above; coarse tiles grouped by fine tile.
  const int blocks = id.lod == 0 ? 1 : spec_.coarse_factor;
  std::vector<std::vector<std::uint32_t>> by_block(std::size_t(blocks * blocks));
  for (int j = 0; j + 1 < ny; ++j) {
    for (int i = 0; i + 1 < nx; ++i) {
      const std::size_t a = at(i, j), b = at(i + 1, j), c = at(i, j + 1), d = at(i + 1, j + 1);
      if (!valid[a] || !valid[b] || !valid[c] || !valid[d]) continue;
      const int bx = std::min(blocks - 1, (cols[std::size_t(i)] - c0) / spec_.tile_samples);
      const int by = std::min(blocks - 1, (rows[std::size_t(j)] - r0) / spec_.tile_samples);
      std::vector<std::uint32_t>& out = by_block[std::size_t(by * blocks + bx)];
      for (const std::size_t v : {c, d, b, c, b, a}) out.push_back(std::uint32_t(v));
    }
  }
  for (const std::vector<std::uint32_t>& block : by_block) {
    if (id.lod != 0) tile.block_first.push_back(std::uint32_t(tile.indices.size()));
    tile.indices.insert(tile.indices.end(), block.begin(), block.end());
  }
  if (id.lod != 0) tile.block_first.push_back(std::uint32_t(tile.indices.size()));

  // Imagery: the first raster under the tile's centre, read over the tile into one texture.
  for (const auto& image : imagery_) {
    std::vector<double> ix(n), iy(n);
    std::vector<int> iok(n, 0);
    for (std::size_t v = 0; v < n; ++v) ix[v] = x[v], iy[v] = y[v];
    OCTTransformEx(image->from_lonlat, int(n), ix.data(), iy.data(), nullptr, iok.data());
    Eigen::AlignedBox2d window;
    std::vector<Eigen::Vector2d> pixel(n);
    for (std::size_t v = 0; v < n; ++v) {
      const double* g = image->inverse;
      pixel[v] = {g[0] + ix[v] * g[1] + iy[v] * g[2], g[3] + ix[v] * g[4] + iy[v] * g[5]};
      if (iok[v] && valid[v]) window.extend(pixel[v]);
    }
    if (window.isEmpty()) continue;
    const double x0 = std::max(0.0, std::floor(window.min().x())),
                 x1 = std::min(double(image->cols), std::ceil(window.max().x()));
    const double y0 = std::max(0.0, std::floor(window.min().y())),
                 y1 = std::min(double(image->rows), std::ceil(window.max().y()));
    const Eigen::Vector2d centre = pixel[at(nx / 2, ny / 2)];
    if (x1 - x0 < 1.0 || y1 - y0 < 1.0 || centre.x() < 0 || centre.y() < 0 ||
        centre.x() > image->cols || centre.y() > image->rows) {
      continue;
    }
    const int size = spec_.texture_px;
    const double read_px = ImageryPixelsRead(image->overview_factors, x1 - x0, y1 - y0, size);
    if (read_px > double(spec_.limits.max_imagery_window_px)) {
      tile.imagery_problem = image->path.string() + ": a tile's texture reads a window of " +
                             std::to_string(std::llround(read_px)) + " px, over the limit of " +
                             std::to_string(spec_.limits.max_imagery_window_px) +
                             " ([level] max_imagery_window_px; overviews, gdaladdo, read fewer)";
      break;
    }
    std::vector<std::uint8_t> rgb(std::size_t(size) * std::size_t(size) * 3);
    GDALRasterIOExtraArg extra;
    INIT_RASTERIO_EXTRA_ARG(extra);
    extra.eResampleAlg = GRIORA_Bilinear;
    int band_map[3] = {1, std::min(2, image->bands), std::min(3, image->bands)};
    if (GDALDatasetRasterIOEx(image->dataset, GF_Read, int(x0), int(y0), int(x1 - x0), int(y1 - y0),
                              rgb.data(), size, size, GDT_Byte, 3, band_map, 3, 3 * size, 1,
                              &extra) != CE_None) {
      // The tile keeps its ground and base colour.
      tile.imagery_problem =
          image->path.string() + ": cannot read imagery (" + QuietGdal::Last("read error") + ")";
      break;
    }
    tile.texture_width = tile.texture_height = size;
    tile.texture_rgba.resize(std::size_t(size) * std::size_t(size) * 4);
    for (std::size_t t = 0; t < std::size_t(size) * std::size_t(size); ++t) {
      for (int k = 0; k < 3; ++k)
        tile.texture_rgba[4 * t + std::size_t(k)] = rgb[3 * t + std::size_t(k)];
      tile.texture_rgba[4 * t + 3] = 255;
    }
    tile.uvs.resize(n);
    for (std::size_t v = 0; v < n; ++v) {
      tile.uvs[v] =
          Eigen::Vector2d((pixel[v].x() - x0) / (x1 - x0), (pixel[v].y() - y0) / (y1 - y0))
              .cast<float>();
    }
    break;
  }

  // Skirts: walls hanging from the edges, so that no crack between a fine and a
  // coarse tile lets the sky through.
  const double depth_m = std::max(20.0, 2.0 * step * raster->metres_per_sample.maxCoeff());
  auto wall = [&](std::size_t u, std::size_t v) {
    if (!valid[u] || !valid[v]) return;
    const std::uint32_t first = std::uint32_t(tile.positions.size());
    for (const std::size_t k : {u, v}) {
      tile.positions.push_back(tile.positions[k] - Eigen::Vector3f(0.f, 0.f, float(depth_m)));
      tile.normals.push_back(tile.normals[k]);
      if (!tile.uvs.empty()) tile.uvs.push_back(tile.uvs[k]);
    }
    for (const std::uint32_t k :
         {std::uint32_t(u), std::uint32_t(v), first + 1, std::uint32_t(u), first + 1, first}) {
      tile.skirt_indices.push_back(k);
    }
  };
  for (int i = 0; i + 1 < nx; ++i)
    wall(at(i, 0), at(i + 1, 0)), wall(at(i, ny - 1), at(i + 1, ny - 1));
  for (int j = 0; j + 1 < ny; ++j)
    wall(at(0, j), at(0, j + 1)), wall(at(nx - 1, j), at(nx - 1, j + 1));
  tile.build_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return tile;
}

std::size_t TerrainTile::bytes() const {
  return positions.size() * 12 + normals.size() * 12 + uvs.size() * 8 +
         (indices.size() + skirt_indices.size() + block_first.size()) * 4 + texture_rgba.size();
}

}  // namespace sandbox::scene
