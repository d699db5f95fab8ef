#pragma once
// The ground's detail textures, made here from noise (no files): four tiling
// RGBA8 layers, grass, rock, snow and sand, each a brightness pattern around
// 0.5 (the shader doubles it) so that they modulate a colour without tinting it.

#include <cstdint>
#include <vector>

namespace sandbox::render {

enum DetailLayer { kGrass = 0, kRock = 1, kSnow = 2, kSand = 3, kNumDetailLayers = 4 };

// `size` x `size` texels a layer, layers one after the other, rows of RGBA.
// The same bytes on every call (a fixed seed): frames are reproducible.
std::vector<std::uint8_t> MakeDetailTextures(int size);

}  // namespace sandbox::render
