#include "sensors/render/material_textures.h"

#include "sensors/render/gpu_mesh.h"
#include "sensors/render/read_back.h"

namespace sandbox::render {

void MaterialTextures::Load(const scene::Level& level, const TextureDecoder& decoder,
                            std::vector<std::string>* warnings) {
  for (std::size_t m = 0; m < level.materials.size(); ++m) {
    const scene::Material& material = level.materials[m];
    auto load = [&](int embedded_index, const std::string& path, const std::string& what,
                    const std::string& fallback, GLint wrap, bool srgb, std::map<int, GLuint>* to) {
      const bool embedded = embedded_index >= 0 && embedded_index < int(level.textures.size());
      if (!embedded && path.empty()) return;
      RgbaImage image;
      const scene::EmbeddedTexture* texture =
          embedded ? &level.textures[std::size_t(embedded_index)] : nullptr;
      const std::string problem = decoder ? decoder(texture, path, &image) : "no decoder";
      if (problem.empty() && image.width > 0 && image.height > 0) {
        // Model files' texture coordinates come from assimp with v = 0 at the
        // image's bottom row (it flips glTF's); GL's t = 0 is the first row given.
        if (what != "lightmap") FlipImage(&image);
        (*to)[int(m)] = UploadTexture(image, wrap, srgb);
      } else {
        warnings->push_back("material '" + material.name + "': " + what + " " +
                            (embedded ? "(embedded)" : path) + " cannot be read (" +
                            (problem.empty() ? "empty" : problem) + "); " + fallback);
      }
    };
    load(material.base_color_texture_embedded, material.base_color_texture_path, "texture",
         "drawn with its base colour", GL_REPEAT, true, &base_);
    load(material.normal_texture_embedded, material.normal_texture_path, "normal map",
         "drawn without it", GL_REPEAT, false, &normal_);
    if (material.lightmap_texture_embedded >= 0) {
      load(material.lightmap_texture_embedded, "", "lightmap", "lit by the sun instead",
           GL_CLAMP_TO_EDGE, true, &lightmap_);
    }
  }
}

MaterialTextures::Ids MaterialTextures::Of(int material) const {
  auto find = [material](const std::map<int, GLuint>& by_material) {
    const auto found = by_material.find(material);
    return found != by_material.end() ? found->second : 0u;
  };
  return {find(base_), find(normal_), find(lightmap_)};
}

void MaterialTextures::Bind(GLenum unit, GLuint texture, bool srgb, bool gamma) {
  glActiveTexture(unit);
  glBindTexture(GL_TEXTURE_2D, texture);
  if (texture != 0 && srgb) {
    // A texture decodes until told otherwise.
    bool& decoding = srgb_decode_.emplace(texture, true).first->second;
    if (decoding != gamma) {
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_SRGB_DECODE_EXT,
                      gamma ? GL_DECODE_EXT : GL_SKIP_DECODE_EXT);
      decoding = gamma;
    }
  }
  glActiveTexture(GL_TEXTURE0);
}

}  // namespace sandbox::render
