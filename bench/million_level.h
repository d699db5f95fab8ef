#pragma once
// The generated 1M-triangle level the benchmarks share: a 1000 x 500 m
// terrain, 1 m cells, heights 5 sin(x / 40) cos(y / 25) m, as glTF + manifest.

#include <filesystem>

namespace sandbox::bench {

// Writes million.gltf, million.bin and million.toml into `dir`; returns the manifest.
std::filesystem::path WriteMillionTriangleLevel(const std::filesystem::path& dir);

}  // namespace sandbox::bench
