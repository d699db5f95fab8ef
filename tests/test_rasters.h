#pragma once
// Small rasters written with GDAL for terrain tests and fuzz seeds: a GeoTIFF
// in WGS84 (EPSG:4326) whose values come from a function.

#include <cpl_conv.h>
#include <gdal.h>
#include <ogr_srs_api.h>

#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace sandbox::testing {

// `cols` x `rows` samples of `spacing_deg` from the north-west corner (lon0,
// lat0), `bands` of `type`, band values from `value(col, row, band)` (none
// written when `value` is empty: a sparse file with SPARSE_OK=TRUE), with
// GDAL creation `options`, in the coordinate system `crs_wkt` (WGS84 when
// empty). Throws std::runtime_error naming the file.
inline void WriteRaster(const std::filesystem::path& file, int cols, int rows, double lon0,
                        double lat0, double spacing_deg, int bands, GDALDataType type,
                        const std::function<double(int, int, int)>& value,
                        std::vector<std::string> options = {}, const std::string& crs_wkt = "") {
  GDALAllRegister();
  std::vector<char*> list;
  for (std::string& option : options) list.push_back(option.data());
  list.push_back(nullptr);
  GDALDatasetH dataset =
      GDALCreate(GDALGetDriverByName("GTiff"), file.c_str(), cols, rows, bands, type, list.data());
  if (dataset == nullptr) throw std::runtime_error(file.string() + ": GDAL cannot create it");
  double gt[6] = {lon0, spacing_deg, 0.0, lat0, 0.0, -spacing_deg};
  GDALSetGeoTransform(dataset, gt);
  if (crs_wkt.empty()) {
    OGRSpatialReferenceH wgs84 = OSRNewSpatialReference(nullptr);
    OSRImportFromEPSG(wgs84, 4326);
    char* wkt = nullptr;
    OSRExportToWkt(wgs84, &wkt);
    GDALSetProjection(dataset, wkt);
    CPLFree(wkt);
    OSRDestroySpatialReference(wgs84);
  } else if (GDALSetProjection(dataset, crs_wkt.c_str()) != CE_None) {
    GDALClose(dataset);
    throw std::runtime_error(file.string() + ": GDAL refuses the coordinate system " + crs_wkt);
  }
  bool written = true;
  if (value) {
    std::vector<double> row(static_cast<std::size_t>(cols));
    for (int b = 1; b <= bands; ++b) {
      for (int r = 0; r < rows; ++r) {
        for (int c = 0; c < cols; ++c) row[std::size_t(c)] = value(c, r, b);
        written = written && GDALRasterIO(GDALGetRasterBand(dataset, b), GF_Write, 0, r, cols, 1,
                                          row.data(), cols, 1, GDT_Float64, 0, 0) == CE_None;
      }
    }
  }
  GDALClose(dataset);
  if (!written) throw std::runtime_error(file.string() + ": GDAL cannot write its samples");
}

}  // namespace sandbox::testing
