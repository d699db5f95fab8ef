#pragma once
// Images through OpenCV: texture decoding for the renderer, and frame writing.

#include <cstdint>
#include <filesystem>
#include <string>

#include "scene/load_limits.h"
#include "sensors/render/renderer.h"

namespace sandbox::app {

// Decodes embedded (PNG, JPEG, ...) or file textures to RGBA with OpenCV.
// Texture files must be regular files within limits.max_file_mb, and a PNG or
// JPEG whose header states more than limits.max_texture_pixels is refused
// before it is decoded (other formats: OpenCV's own limit of 2^30 pixels).
render::TextureDecoder OpenCvTextureDecoder(const scene::LoadLimits& limits = {});

// The width and height a PNG or JPEG states in its header; false for other
// formats or a header cut short.
bool ImageHeaderSize(const std::uint8_t* data, std::size_t size, std::uint32_t* width,
                     std::uint32_t* height);

// Writes a frame's colour; the format follows the file's extension (.jpg,
// .png, ...). Throws std::runtime_error naming the file when it cannot.
void WriteColor(const render::Frame& frame, const std::string& path);
// The colour image as a JPEG file's bytes (OpenCV's encoder), in memory.
std::string EncodeJpeg(const render::Frame& frame, int quality = 85);
// A written frame's colour as compressed bytes: the file itself when it is a
// JPEG (or, with `png_too`, a PNG), else the frame encoded as JPEG; *format
// says which ("jpeg" or "png").
std::string CompressedColor(const render::Frame& frame, const std::filesystem::path& color_file,
                            bool png_too, std::string* format);
// Writes depth as a 16-bit PNG in millimetres (0: nothing within range).
void WriteDepthMillimetres(const render::Frame& frame, const std::string& path);
// Writes depth as a NumPy .npy file: float32 metres, shape (height, width),
// row 0 at the top, +inf where nothing is (numpy.load, or readNPY in MATLAB).
void WriteDepthNpy(const render::Frame& frame, const std::string& path);
// Writes segment ids as a 16-bit PNG (0: sky; the legend names the others).
void WriteSegmentation(const render::Frame& frame, const std::string& path);
// Writes camera-frame normals (x forward, y left, z up) as an 8-bit RGB PNG,
// each channel round(255 (n + 1) / 2); black (0, 0, 0) where nothing is.
void WriteNormals(const render::Frame& frame, const std::string& path);
// Writes normals as a NumPy .npy file: float32, shape (height, width, 3), 0 where nothing is.
void WriteNormalsNpy(const render::Frame& frame, const std::string& path);
// Writes depth as OpenEXR: one float32 channel (Y) in metres, ZIP compressed,
// +inf where nothing is. Turns on OpenCV's EXR codec (off by default).
void WriteDepthExr(const render::Frame& frame, const std::string& path);

}  // namespace sandbox::app
