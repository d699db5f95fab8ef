#pragma once
// The level materials' textures on the GPU (base colour, normal map,
// lightmap), decoded once by the decoder the app gives, and bound with the
// sRGB decoding the frame's shading wants.

#include <map>
#include <string>
#include <vector>

#include "scene/level.h"
#include "sensors/render/gl.h"
#include "sensors/render/renderer.h"

namespace sandbox::render {

class MaterialTextures {
 public:
  // Adds a warning for each texture that cannot be decoded (the material
  // is then drawn without it).
  void Load(const scene::Level& level, const TextureDecoder& decoder,
            std::vector<std::string>* warnings);

  struct Ids {
    GLuint base{0}, normal{0}, lightmap{0};  // 0: none
  };
  Ids Of(int material) const;

  // Binds `texture` (0: none) to `unit`; colour textures (sRGB) are decoded
  // to linear light by the sampler with `gamma` (gamma-correct shading) and
  // read as display values without. Leaves unit 0 active.
  void Bind(GLenum unit, GLuint texture, bool srgb, bool gamma);

 private:
  std::map<int, GLuint> base_, normal_, lightmap_;  // by material
  std::map<GLuint, bool> srgb_decode_;              // by colour texture: decoding to linear now
};

}  // namespace sandbox::render
