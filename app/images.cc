#include "app/images.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "scene/files.h"

namespace sandbox::app {

bool ImageHeaderSize(const std::uint8_t* data, std::size_t size, std::uint32_t* width,
                     std::uint32_t* height) {
  auto big_endian = [&](std::size_t at, int n) {
    std::uint32_t v = 0;
    for (int i = 0; i < n; ++i) v = v << 8 | data[at + std::size_t(i)];
    return v;
  };
  // PNG: the signature, then IHDR with width and height.
  if (size >= 24 && std::memcmp(data, "\x89PNG\r\n\x1a\n", 8) == 0) {
    *width = big_endian(16, 4), *height = big_endian(20, 4);
    return true;
  }
  // JPEG: markers up to a start of frame (SOF0-SOF15 but DHT, JPG, DAC).
  if (size < 4 || data[0] != 0xff || data[1] != 0xd8) return false;
  std::size_t at = 2;
  while (at + 9 <= size) {
    if (data[at] != 0xff) return false;
    const std::uint8_t marker = data[at + 1];
    if (marker == 0xff) {  // fill byte
      ++at;
      continue;
    }
    if (marker >= 0xc0 && marker <= 0xcf && marker != 0xc4 && marker != 0xc8 && marker != 0xcc) {
      *height = big_endian(at + 5, 2), *width = big_endian(at + 7, 2);
      return true;
    }
    at += 2 + big_endian(at + 2, 2);
  }
  return false;
}

render::TextureDecoder OpenCvTextureDecoder(const scene::LoadLimits& limits) {
  return [limits](const scene::EmbeddedTexture* embedded, const std::string& path,
                  render::RgbaImage* image) -> std::string {
    cv::Mat decoded;
    auto too_big = [&](std::uint64_t width, std::uint64_t height) {
      return width * height > limits.max_texture_pixels
                 ? std::to_string(width) + " x " + std::to_string(height) +
                       " pixels, over the limit of " + std::to_string(limits.max_texture_pixels) +
                       " ([level] max_texture_pixels)"
                 : std::string();
    };
    if (embedded != nullptr && embedded->height > 0) {  // raw RGBA texels
      if (std::string problem =
              too_big(std::uint64_t(embedded->width), std::uint64_t(embedded->height));
          !problem.empty()) {
        return problem;
      }
      image->width = embedded->width;
      image->height = embedded->height;
      image->rgba = embedded->bytes;
      return "";
    }
    std::vector<std::uint8_t> file_bytes;
    const std::vector<std::uint8_t>* bytes = embedded != nullptr ? &embedded->bytes : nullptr;
    if (embedded == nullptr) {
      // Only regular files (a FIFO would block), within the limits.
      if (std::string problem = scene::RegularFileProblem(path); !problem.empty()) return problem;
      try {
        limits.CheckFileSize(path);
      } catch (const scene::LevelError& error) {
        return error.what();
      }
      file_bytes.resize(scene::FileBytes(path));
      std::ifstream in(path, std::ios::binary);
      if (!in.read(reinterpret_cast<char*>(file_bytes.data()),
                   std::streamsize(file_bytes.size()))) {
        return "cannot be read";
      }
      bytes = &file_bytes;
    }
    std::uint32_t width = 0, height = 0;
    if (ImageHeaderSize(bytes->data(), bytes->size(), &width, &height)) {
      if (std::string problem = too_big(width, height); !problem.empty()) return problem;
    }
    const cv::Mat encoded(1, int(bytes->size()), CV_8U, const_cast<std::uint8_t*>(bytes->data()));
    try {
      decoded = cv::imdecode(encoded, cv::IMREAD_UNCHANGED);
    } catch (const cv::Exception& error) {
      return std::string("OpenCV cannot decode it: ") + error.what();
    }
    if (decoded.empty()) return "OpenCV cannot decode it";
    if (decoded.depth() != CV_8U) decoded.convertTo(decoded, CV_8U, 1.0 / 257.0);
    const int code = decoded.channels() == 1   ? cv::COLOR_GRAY2RGBA
                     : decoded.channels() == 3 ? cv::COLOR_BGR2RGBA
                                               : cv::COLOR_BGRA2RGBA;
    cv::cvtColor(decoded, decoded, code);
    image->width = decoded.cols;
    image->height = decoded.rows;
    image->rgba.assign(decoded.data, decoded.data + decoded.total() * 4);
    return "";
  };
}

namespace {

// cv::imwrite, failing with the path whether OpenCV returns false or throws.
void Write(const cv::Mat& image, const std::string& path, const std::vector<int>& params = {}) {
  bool written = false;
  try {
    written = cv::imwrite(path, image, params);
  } catch (const cv::Exception&) {
    written = false;
  }
  if (!written) throw std::runtime_error("cannot write " + path);
}

}  // namespace

void WriteColor(const render::Frame& frame, const std::string& path) {
  cv::Mat rgb(frame.height, frame.width, CV_8UC3, const_cast<std::uint8_t*>(frame.rgb.data()));
  cv::Mat bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  Write(bgr, path);
}

std::string CompressedColor(const render::Frame& frame, const std::filesystem::path& color_file,
                            bool png_too, std::string* format) {
  const std::filesystem::path kind = color_file.extension();
  if (kind == ".jpg" || (png_too && kind == ".png")) {
    std::ifstream in(color_file, std::ios::binary);
    std::ostringstream read;
    read << in.rdbuf();
    std::string bytes = read.str();
    if (!bytes.empty()) {
      *format = kind == ".png" ? "png" : "jpeg";
      return bytes;
    }
  }
  *format = "jpeg";
  return EncodeJpeg(frame);
}

std::string EncodeJpeg(const render::Frame& frame, int quality) {
  cv::Mat rgb(frame.height, frame.width, CV_8UC3, const_cast<std::uint8_t*>(frame.rgb.data()));
  cv::Mat bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  std::vector<std::uint8_t> bytes;
  if (!cv::imencode(".jpg", bgr, bytes, {cv::IMWRITE_JPEG_QUALITY, quality}))
    throw std::runtime_error("cannot encode a JPEG");
  return std::string(bytes.begin(), bytes.end());
}

void WriteDepthMillimetres(const render::Frame& frame, const std::string& path) {
  cv::Mat depth(frame.height, frame.width, CV_16U);
  for (int i = 0; i < frame.width * frame.height; ++i) {
    const float d = frame.depth_m[std::size_t(i)];
    depth.at<std::uint16_t>(i / frame.width, i % frame.width) =
        std::isfinite(d) && d * 1000.f < 65535.f ? std::uint16_t(std::lround(d * 1000.f)) : 0;
  }
  Write(depth, path);
}

namespace {

// A float32 NumPy .npy file of the given shape (row-major).
void WriteNpy(const float* data, const std::vector<int>& shape, const std::string& path) {
  // Format 1.0: magic, version, a little-endian header length, then a Python
  // dict literal padded with spaces and a newline to a multiple of 64 bytes.
  std::string dims;  // as numpy writes them: "(2, 3)", "(5,)"
  std::size_t count = 1;
  for (const int n : shape) {
    dims += (dims.empty() ? "" : ", ") + std::to_string(n);
    count *= std::size_t(n);
  }
  if (shape.size() == 1) dims += ",";
  std::string header = "{'descr': '<f4', 'fortran_order': False, 'shape': (" + dims + "), }";
  const std::size_t preamble = 10;
  header.append(63 - (preamble + header.size()) % 64, ' ');
  header += '\n';
  std::ofstream out(path, std::ios::binary);
  out.write("\x93NUMPY\x01\x00", 8);
  const char length[2] = {char(header.size() & 0xff), char(header.size() >> 8)};
  out.write(length, 2);
  out << header;
  static_assert(sizeof(float) == 4, "float32");
  out.write(reinterpret_cast<const char*>(data),
            std::streamsize(count * sizeof(float)));  // x86 and ARM: little-endian
  if (!out.good()) throw std::runtime_error("cannot write " + path);
}

}  // namespace

void WriteDepthNpy(const render::Frame& frame, const std::string& path) {
  WriteNpy(frame.depth_m.data(), {frame.height, frame.width}, path);
}

void WriteSegmentation(const render::Frame& frame, const std::string& path) {
  cv::Mat ids(frame.height, frame.width, CV_16U);
  for (int i = 0; i < frame.width * frame.height; ++i) {
    ids.at<std::uint16_t>(i / frame.width, i % frame.width) =
        std::uint16_t(std::min<std::uint32_t>(frame.segment[std::size_t(i)], 65535u));
  }
  Write(ids, path);
}

void WriteNormals(const render::Frame& frame, const std::string& path) {
  cv::Mat bgr(frame.height, frame.width, CV_8UC3);
  for (int i = 0; i < frame.width * frame.height; ++i) {
    const float* n = &frame.normal_C[3 * std::size_t(i)];
    cv::Vec3b& pixel = bgr.at<cv::Vec3b>(i / frame.width, i % frame.width);
    const bool nothing = n[0] == 0.f && n[1] == 0.f && n[2] == 0.f;
    for (int c = 0; c < 3; ++c) {
      pixel[2 - c] =
          nothing ? 0
                  : std::uint8_t(std::lround(std::clamp(0.5f * (n[c] + 1.f), 0.f, 1.f) * 255.f));
    }
  }
  Write(bgr, path);
}

void WriteNormalsNpy(const render::Frame& frame, const std::string& path) {
  WriteNpy(frame.normal_C.data(), {frame.height, frame.width, 3}, path);
}

void WriteDepthExr(const render::Frame& frame, const std::string& path) {
  // OpenCV reads this once, at its first EXR file.
  static std::once_flag enabled;
  std::call_once(enabled, [] { setenv("OPENCV_IO_ENABLE_OPENEXR", "1", 0); });
  const cv::Mat depth(frame.height, frame.width, CV_32F, const_cast<float*>(frame.depth_m.data()));
  Write(depth, path, {cv::IMWRITE_EXR_TYPE, cv::IMWRITE_EXR_TYPE_FLOAT});
}

}  // namespace sandbox::app
