// Fuzz target: bytes as a terrain raster (a GeoTIFF),
// held in GDAL's memory (/vsimem/) and used as the elevation and the imagery
// of a [[terrain]]: opened, its budgets checked, a fine and a coarse tile
// built, as the streamer would.

#include <cpl_vsi.h>
#include <gdal.h>

#include <cstdint>
#include <exception>
#include <string>

#include "scene/level.h"
#include "scene/terrain_source.h"

using namespace sandbox::scene;

// GDAL's GeoTIFF driver only (the format the docs name): every other driver's
// probing is GDAL's own code, uninstrumented, and took most of each run.
extern "C" int LLVMFuzzerInitialize(int*, char***) {
  TerrainSpec none;
  try {
    const TerrainSource registers(none);  // GDAL's drivers, registered once as the code does
  } catch (const std::exception&) {
  }
  for (int d = GDALGetDriverCount() - 1; d >= 0; --d) {
    GDALDriverH driver = GDALGetDriver(d);
    if (std::string(GDALGetDriverShortName(driver)) != "GTiff") GDALDeregisterDriver(driver);
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const char* name = "/vsimem/fuzz.tif";
  VSILFILE* file = VSIFileFromMemBuffer(name, const_cast<GByte*>(data), vsi_l_offset(size), FALSE);
  if (file == nullptr) return 0;
  VSIFCloseL(file);
  TerrainSpec spec;
  spec.elevation = {name};
  spec.imagery = {name};
  spec.anchor = {46.0, 8.0, 500.0};
  spec.tile_samples = 16, spec.coarse_factor = 4, spec.texture_px = 8;
  spec.collision_radius_m = 500, spec.view_radius_m = 2000;
  try {
    const TerrainSource source(spec);
    if (source.num_usable() > 0) {
      try {
        source.CheckBudgets();
      } catch (const LevelError&) {
        VSIUnlink(name);
        return 0;  // refused at load: never built
      }
      for (const int lod : {0, 1}) {
        try {
          source.Build(TileId{lod, 0, 0, 0});
        } catch (const std::runtime_error&) {
        }
      }
    }
  } catch (const LevelError&) {
  }
  VSIUnlink(name);
  return 0;
}
