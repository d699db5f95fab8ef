// Generates the bundled highlands (assets/highlands/level.toml): an elevation
// raster of 4000 x 4000 samples at 30 m (120 km a side, float metres above
// the WGS84 ellipsoid) and an imagery raster at 60 m coloured by height and
// slope, both GeoTIFF on UTM zone 32 north, tiled and compressed. Ridged
// fractal noise makes the ranges, a warp bends them, valleys are carved
// where the ridges fade; the airfield (the world origin) is flattened, and
// the ground falls to sea level at the edges. Deterministic.
//
//   make_highlands OUT_DIR

#include <cpl_conv.h>
#include <gdal.h>
#include <ogr_srs_api.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "assets/generators/highlands_terrain.h"

namespace sandbox::assets::highlands {
namespace {

// 2-D gradient noise (Perlin's, with a hashed gradient per lattice point), in [-1, 1].
double Noise(double x, double y, std::uint32_t seed) {
  auto hash = [seed](std::int64_t i, std::int64_t j) {
    std::uint64_t h = std::uint64_t(i) * 0x9E3779B97F4A7C15ull ^
                      std::uint64_t(j) * 0xC2B2AE3D27D4EB4Full ^
                      std::uint64_t(seed) * 0x165667B19E3779F9ull;
    h ^= h >> 31, h *= 0xBF58476D1CE4E5B9ull, h ^= h >> 29;
    return h;
  };
  auto gradient = [&](std::int64_t i, std::int64_t j, double dx, double dy) {
    const double angle = double(hash(i, j) & 0xffff) / 65536.0 * 6.283185307179586;
    return std::cos(angle) * dx + std::sin(angle) * dy;
  };
  const double fx = std::floor(x), fy = std::floor(y);
  const std::int64_t i = std::int64_t(fx), j = std::int64_t(fy);
  const double dx = x - fx, dy = y - fy;
  auto fade = [](double t) { return t * t * t * (t * (t * 6 - 15) + 10); };
  const double u = fade(dx), v = fade(dy);
  const double a = gradient(i, j, dx, dy), b = gradient(i + 1, j, dx - 1, dy);
  const double c = gradient(i, j + 1, dx, dy - 1), d = gradient(i + 1, j + 1, dx - 1, dy - 1);
  return 1.41 * ((a + (b - a) * u) * (1 - v) + (c + (d - c) * u) * v);
}

// Height above the ellipsoid at (x, y) metres east and north of the airfield.
double Height(double x, double y) {
  // A warp, so ridges bend as real ones do.
  const double wx = x + 6000.0 * Noise(x / 30000.0, y / 30000.0, 7);
  const double wy = y + 6000.0 * Noise(x / 30000.0 + 5.2, y / 30000.0 + 1.3, 8);
  double ridges = 0.0, amplitude = 1.0, weight = 1.0, frequency = 1.0 / 24000.0;
  for (int octave = 0; octave < 9; ++octave) {
    double r = 1.0 - std::abs(Noise(wx * frequency, wy * frequency, 11 + std::uint32_t(octave)));
    r = r * r * weight;
    weight = std::clamp(r * 1.6, 0.0, 1.0);
    ridges += r * amplitude;
    amplitude *= 0.48, frequency *= 2.05;
  }
  const double massif = 0.5 + 0.5 * Noise(x / 70000.0 + 3.1, y / 70000.0 - 2.4, 3);  // where high
  double h = 300.0 + 700.0 * massif + 4400.0 * massif * std::max(0.0, ridges - 0.3);
  // The airfield: flat within 1.5 km, blended over the next 2.5 km.
  const double r = std::hypot(x, y);
  const double flat = std::clamp((r - 1500.0) / 2500.0, 0.0, 1.0);
  h = kAirfieldHeight_m + (h - kAirfieldHeight_m) * flat * flat * (3 - 2 * flat);
  // The edges: down to sea level.
  const double west = x + kWestOfAirfield_m, east = kSamples * kSpacing_m - west;
  const double south = y + 0.5 * kSamples * kSpacing_m, north = kSamples * kSpacing_m - south;
  const double edge = std::clamp(std::min({west, east, south, north}) / kEdgeTaper_m, 0.0, 1.0);
  return h * edge * edge * (3 - 2 * edge);
}

void Fail(const std::string& what) {
  std::fprintf(stderr, "make_highlands: %s: %s\n", what.c_str(), CPLGetLastErrorMsg());
  std::exit(1);
}

// A GeoTIFF on UTM 32N whose north-west corner is at (west_m, north_m) in the
// airfield's easting and northing.
GDALDatasetH Create(const std::string& path, int size, int bands, GDALDataType type,
                    double spacing_m, double airfield_e, double airfield_n) {
  GDALDriverH driver = GDALGetDriverByName("GTiff");
  const char* options[] = {"TILED=YES", "COMPRESS=DEFLATE", "ZLEVEL=1",
                           type == GDT_Float32 ? "PREDICTOR=3" : "PREDICTOR=2", nullptr};
  GDALDatasetH dataset =
      GDALCreate(driver, path.c_str(), size, size, bands, type, const_cast<char**>(options));
  if (dataset == nullptr) Fail("cannot create " + path);
  const double west = airfield_e - kWestOfAirfield_m;
  const double north = airfield_n + 0.5 * kSamples * kSpacing_m;
  double gt[6] = {west, spacing_m, 0.0, north, 0.0, -spacing_m};
  GDALSetGeoTransform(dataset, gt);
  OGRSpatialReferenceH utm = OSRNewSpatialReference(nullptr);
  OSRImportFromEPSG(utm, 32600 + kUtmZone);
  GDALSetSpatialRef(dataset, utm);
  OSRDestroySpatialReference(utm);
  return dataset;
}

}  // namespace
}  // namespace sandbox::assets::highlands

int main(int argc, char** argv) {
  using namespace sandbox::assets::highlands;
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_highlands OUT_DIR\n");
    return 2;
  }
  const std::filesystem::path out = argv[1];
  std::filesystem::create_directories(out);
  GDALAllRegister();
  // The airfield's UTM coordinates.
  OGRSpatialReferenceH wgs84 = OSRNewSpatialReference(nullptr),
                       utm = OSRNewSpatialReference(nullptr);
  OSRSetWellKnownGeogCS(wgs84, "WGS84");
  OSRImportFromEPSG(utm, 32600 + kUtmZone);
  OSRSetAxisMappingStrategy(wgs84, OAMS_TRADITIONAL_GIS_ORDER);
  OSRSetAxisMappingStrategy(utm, OAMS_TRADITIONAL_GIS_ORDER);
  OGRCoordinateTransformationH to_utm = OCTNewCoordinateTransformation(wgs84, utm);
  double e = kAnchorLongitude_deg, n = kAnchorLatitude_deg;
  if (!to_utm || !OCTTransform(to_utm, 1, &e, &n, nullptr)) Fail("no UTM transformation");

  // Elevation, row by row (north first).
  GDALDatasetH elevation =
      Create((out / "elevation.tif").string(), kSamples, 1, GDT_Float32, kSpacing_m, e, n);
  std::vector<float> row(kSamples);
  for (int r = 0; r < kSamples; ++r) {
    const double y = 0.5 * kSamples * kSpacing_m - (r + 0.5) * kSpacing_m;
    for (int c = 0; c < kSamples; ++c) {
      row[std::size_t(c)] = float(Height(-kWestOfAirfield_m + (c + 0.5) * kSpacing_m, y));
    }
    if (GDALRasterIO(GDALGetRasterBand(elevation, 1), GF_Write, 0, r, kSamples, 1, row.data(),
                     kSamples, 1, GDT_Float32, 0, 0) != CE_None) {
      Fail("cannot write elevation.tif");
    }
  }
  GDALClose(elevation);

  // Imagery: grass low, forest on the slopes, rock higher and steep, snow above 2600 m, sand
  // at sea level.
  const int size = int(kSamples * kSpacing_m / kImagerySpacing_m);
  GDALDatasetH imagery =
      Create((out / "imagery.tif").string(), size, 3, GDT_Byte, kImagerySpacing_m, e, n);
  std::vector<std::uint8_t> rgb(std::size_t(size) * 3);
  const int map[3] = {1, 2, 3};
  for (int r = 0; r < size; ++r) {
    const double y = 0.5 * kSamples * kSpacing_m - (r + 0.5) * kImagerySpacing_m;
    for (int c = 0; c < size; ++c) {
      const double x = -kWestOfAirfield_m + (c + 0.5) * kImagerySpacing_m;
      const double h = Height(x, y);
      const double slope =
          std::hypot(Height(x + 30, y) - Height(x - 30, y), Height(x, y + 30) - Height(x, y - 30)) /
          60.0;
      const double jitter = 0.08 * Noise(x / 400.0, y / 400.0, 21);
      double cr = 0.36, cg = 0.52, cb = 0.24;  // grass
      auto blend = [&](double t, double r2, double g2, double b2) {
        t = std::clamp(t, 0.0, 1.0);
        cr += (r2 - cr) * t, cg += (g2 - cg) * t, cb += (b2 - cb) * t;
      };
      blend((h - 700.0) / 400.0 + jitter * 4, 0.20, 0.34, 0.17);                       // forest
      blend((h - 1900.0) / 300.0 + (slope - 0.6) * 2 + jitter * 4, 0.48, 0.45, 0.42);  // rock
      blend((h - 2600.0) / 200.0 - (slope - 0.8) + jitter * 3, 0.93, 0.94, 0.97);      // snow
      blend(1.0 - h / 40.0, 0.76, 0.70, 0.50);                                         // sand
      const double shade = 1.0 + jitter;
      rgb[3 * std::size_t(c) + 0] = std::uint8_t(std::clamp(255.0 * cr * shade, 0.0, 255.0));
      rgb[3 * std::size_t(c) + 1] = std::uint8_t(std::clamp(255.0 * cg * shade, 0.0, 255.0));
      rgb[3 * std::size_t(c) + 2] = std::uint8_t(std::clamp(255.0 * cb * shade, 0.0, 255.0));
    }
    if (GDALDatasetRasterIO(imagery, GF_Write, 0, r, size, 1, rgb.data(), size, 1, GDT_Byte, 3,
                            const_cast<int*>(map), 3, 3 * size, 1) != CE_None) {
      Fail("cannot write imagery.tif");
    }
  }
  GDALClose(imagery);
  OCTDestroyCoordinateTransformation(to_utm);
  OSRDestroySpatialReference(wgs84);
  OSRDestroySpatialReference(utm);
  std::printf("make_highlands: %s/elevation.tif (%d x %d at %.0f m), imagery.tif (%d x %d)\n",
              out.c_str(), kSamples, kSamples, kSpacing_m, size, size);
  return 0;
}
