#include "app/images.h"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <vector>

namespace sandbox::app {

sensors::TextureDecoder OpenCvTextureDecoder() {
  return [](const scene::EmbeddedTexture* embedded, const std::string& path,
            sensors::RgbaImage* image) {
    cv::Mat decoded;
    if (embedded != nullptr && embedded->height > 0) {  // raw RGBA texels
      image->width = embedded->width;
      image->height = embedded->height;
      image->rgba = embedded->bytes;
      return true;
    }
    if (embedded != nullptr) {
      const cv::Mat bytes(1, int(embedded->bytes.size()), CV_8U,
                          const_cast<std::uint8_t*>(embedded->bytes.data()));
      decoded = cv::imdecode(bytes, cv::IMREAD_UNCHANGED);
    } else {
      decoded = cv::imread(path, cv::IMREAD_UNCHANGED);
    }
    if (decoded.empty()) return false;
    if (decoded.depth() != CV_8U) decoded.convertTo(decoded, CV_8U, 1.0 / 257.0);
    const int code = decoded.channels() == 1   ? cv::COLOR_GRAY2RGBA
                     : decoded.channels() == 3 ? cv::COLOR_BGR2RGBA
                                               : cv::COLOR_BGRA2RGBA;
    cv::cvtColor(decoded, decoded, code);
    image->width = decoded.cols;
    image->height = decoded.rows;
    image->rgba.assign(decoded.data, decoded.data + decoded.total() * 4);
    return true;
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

void WriteColor(const sensors::Frame& frame, const std::string& path) {
  cv::Mat rgb(frame.height, frame.width, CV_8UC3, const_cast<std::uint8_t*>(frame.rgb.data()));
  cv::Mat bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  Write(bgr, path);
}

void WriteDepthMillimetres(const sensors::Frame& frame, const std::string& path) {
  cv::Mat depth(frame.height, frame.width, CV_16U);
  for (int i = 0; i < frame.width * frame.height; ++i) {
    const float d = frame.depth_m[std::size_t(i)];
    depth.at<std::uint16_t>(i / frame.width, i % frame.width) =
        std::isfinite(d) && d * 1000.f < 65535.f ? std::uint16_t(std::lround(d * 1000.f)) : 0;
  }
  Write(depth, path);
}

void WriteDepthNpy(const sensors::Frame& frame, const std::string& path) {
  // Format 1.0: magic, version, a little-endian header length, then a Python
  // dict literal padded with spaces and a newline to a multiple of 64 bytes.
  std::string header = "{'descr': '<f4', 'fortran_order': False, 'shape': (" +
                       std::to_string(frame.height) + ", " + std::to_string(frame.width) + "), }";
  const std::size_t preamble = 10;
  header.append(63 - (preamble + header.size()) % 64, ' ');
  header += '\n';
  std::ofstream out(path, std::ios::binary);
  out.write("\x93NUMPY\x01\x00", 8);
  const char length[2] = {char(header.size() & 0xff), char(header.size() >> 8)};
  out.write(length, 2);
  out << header;
  static_assert(sizeof(float) == 4, "float32");
  out.write(reinterpret_cast<const char*>(frame.depth_m.data()),
            std::streamsize(frame.depth_m.size() * sizeof(float)));  // x86 and ARM: little-endian
  if (!out.good()) throw std::runtime_error("cannot write " + path);
}

void WriteDepthExr(const sensors::Frame& frame, const std::string& path) {
  // OpenCV reads this once, at its first EXR file.
  static std::once_flag enabled;
  std::call_once(enabled, [] { setenv("OPENCV_IO_ENABLE_OPENEXR", "1", 0); });
  const cv::Mat depth(frame.height, frame.width, CV_32F, const_cast<float*>(frame.depth_m.data()));
  Write(depth, path, {cv::IMWRITE_EXR_TYPE, cv::IMWRITE_EXR_TYPE_FLOAT});
}

}  // namespace sandbox::app
