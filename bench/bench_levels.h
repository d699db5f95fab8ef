#pragma once
// What the benchmarks share: generated terrain levels, a median and the
// machine they ran on.

#include <filesystem>
#include <string>
#include <vector>

namespace sandbox::bench {

// A terrain of cols x rows 1 m cells (2 cols rows triangles) with its corner
// at (x0, y0), heights 5 sin(x / 40) cos(y / 25) m, as NAME.gltf, NAME.bin and
// NAME.toml in `dir`; returns the manifest.
std::filesystem::path WriteTerrainLevel(const std::filesystem::path& dir, const std::string& name,
                                        int cols, int rows, double x0 = 0.0, double y0 = 0.0);

// The 1M-triangle level: a 1000 x 500 m terrain from the origin, "million".
std::filesystem::path WriteMillionTriangleLevel(const std::filesystem::path& dir);

double Median(std::vector<double> values);

// The machine, for the first line of a benchmark's output (figures differ
// by about 2x between machines of one kind): "machine: <CPU model>, <n>
// logical CPUs", the model from /proc/cpuinfo ("unknown CPU" without it).
std::string Machine();

}  // namespace sandbox::bench
