#pragma once
// The bundled highlands (assets/highlands): a synthetic mountain range of
// 120 km x 120 km on a UTM grid, anchored on the Earth. The generator writes
// it as GeoTIFF rasters; tests read those files themselves (with GDAL).

namespace sandbox::assets::highlands {

// The airfield: the world origin, on the ground (WGS84 latitude, longitude, height).
constexpr double kAnchorLatitude_deg = 46.5;
constexpr double kAnchorLongitude_deg = 8.2;
constexpr double kAirfieldHeight_m = 450.0;

constexpr int kUtmZone = 32;                 // north; EPSG 32632
constexpr double kSpacing_m = 30.0;          // elevation samples
constexpr int kSamples = 4000;               // a side: 120 km
constexpr double kWestOfAirfield_m = 10000;  // the raster's west edge, from the airfield
constexpr double kImagerySpacing_m = 60.0;   // the draped imagery
constexpr double kEdgeTaper_m = 6000.0;      // the ground falls to height 0 at the edges

}  // namespace sandbox::assets::highlands
