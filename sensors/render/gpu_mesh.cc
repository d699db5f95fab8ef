#include "sensors/render/gpu_mesh.h"

#include <cstdint>

#include "sensors/render/renderer.h"

namespace sandbox::render {

GpuMesh Upload(const MeshData& data, int material, GLenum usage) {
  GpuMesh mesh;
  mesh.material = material;
  const std::vector<std::uint32_t>& indices = data.lods ? data.lods->indices : *data.indices;
  mesh.index_count = GLsizei(data.lods ? data.lods->levels[0].count : indices.size());
  if (data.lods != nullptr && data.lods->levels.size() > 1) mesh.lods = data.lods->levels;
  const std::size_t n = data.positions->size();
  glGenVertexArrays(1, &mesh.vao);
  glBindVertexArray(mesh.vao);
  auto attribute = [&](GLuint* buffer, GLuint location, int size, const void* bytes,
                       std::size_t count) {
    glGenBuffers(1, buffer);
    glBindBuffer(GL_ARRAY_BUFFER, *buffer);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(count), bytes, usage);
    glEnableVertexAttribArray(location);
    glVertexAttribPointer(location, size, GL_FLOAT, GL_FALSE, 0, nullptr);
  };
  attribute(&mesh.positions, 0, 3, data.positions->data(), n * 12);
  attribute(&mesh.normals, 1, 3, data.normals->data(), data.normals->size() * 12);
  if (data.uvs != nullptr && data.uvs->size() == n) {
    attribute(&mesh.uvs, 2, 2, data.uvs->data(), n * 8);
  } else {
    glVertexAttrib2f(2, 0.f, 0.f);
  }
  if (data.lightmap_uvs != nullptr && data.lightmap_uvs->size() == n) {
    attribute(&mesh.lightmap_uvs, 3, 2, data.lightmap_uvs->data(), n * 8);
  } else {
    glVertexAttrib2f(3, 0.f, 0.f);
  }
  if (data.colors != nullptr && data.colors->size() == n) {
    attribute(&mesh.colors, 4, 4, data.colors->data(), n * 16);
  } else {
    glVertexAttrib4f(4, 1.f, 1.f, 1.f, 1.f);
  }
  if (data.vertex_segments != nullptr && data.vertex_segments->size() == n) {
    glGenBuffers(1, &mesh.segments);
    glBindBuffer(GL_ARRAY_BUFFER, mesh.segments);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(n * 4), data.vertex_segments->data(), GL_STATIC_DRAW);
    glEnableVertexAttribArray(5);
    glVertexAttribIPointer(5, 1, GL_UNSIGNED_INT, 0, nullptr);
  } else {
    glVertexAttribI1ui(5, 0);
  }
  glGenBuffers(1, &mesh.indices);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, mesh.indices);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(indices.size() * 4), indices.data(),
               GL_STATIC_DRAW);
  glBindVertexArray(0);
  return mesh;
}

void Free(const GpuMesh& m) {
  const GLuint buffers[] = {m.positions, m.normals,  m.uvs,     m.lightmap_uvs,
                            m.colors,    m.segments, m.indices, m.triangle_segment_buffer};
  for (const GLuint buffer : buffers) {
    if (buffer != 0) glDeleteBuffers(1, &buffer);
  }
  if (m.triangle_segments != 0) glDeleteTextures(1, &m.triangle_segments);
  glDeleteVertexArrays(1, &m.vao);
}

void SetTriangleSegments(GpuMesh* mesh, const std::vector<std::uint32_t>& ids) {
  if (ids.empty()) return;
  glGenBuffers(1, &mesh->triangle_segment_buffer);
  glBindBuffer(GL_TEXTURE_BUFFER, mesh->triangle_segment_buffer);
  glBufferData(GL_TEXTURE_BUFFER, GLsizeiptr(ids.size() * 4), ids.data(), GL_STATIC_DRAW);
  glGenTextures(1, &mesh->triangle_segments);
  glBindTexture(GL_TEXTURE_BUFFER, mesh->triangle_segments);
  glTexBuffer(GL_TEXTURE_BUFFER, GL_R32UI, mesh->triangle_segment_buffer);
}

std::vector<std::uint32_t> WeldedIndices(const std::vector<Eigen::Vector3f>& positions,
                                         const std::vector<Eigen::Vector3f>& normals,
                                         const std::vector<Eigen::Vector2f>& uvs,
                                         const std::vector<Eigen::Vector2f>& lightmap_uvs,
                                         const std::vector<Eigen::Vector4f>& colors,
                                         const std::vector<std::uint32_t>* ids,
                                         const std::vector<std::uint32_t>& indices) {
  const std::size_t n = positions.size();
  auto stream = [n](const auto& values) {
    return VertexStream{values.size() == n ? values.data() : nullptr, sizeof(values[0])};
  };
  return WeldIdentical(indices, n,
                       {stream(positions), stream(normals), stream(uvs), stream(lightmap_uvs),
                        stream(colors), ids ? stream(*ids) : VertexStream{nullptr, 4}});
}

GLuint UploadTexture(const RgbaImage& image, GLint wrap, bool srgb) {
  GLuint id = 0;
  glGenTextures(1, &id);
  glBindTexture(GL_TEXTURE_2D, id);
  glTexImage2D(GL_TEXTURE_2D, 0, srgb ? GL_SRGB8_ALPHA8 : GL_RGBA8, image.width, image.height, 0,
               GL_RGBA, GL_UNSIGNED_BYTE, image.rgba.data());
  glGenerateMipmap(GL_TEXTURE_2D);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, wrap);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, wrap);
  return id;
}

}  // namespace sandbox::render
