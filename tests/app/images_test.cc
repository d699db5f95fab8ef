// Depth files as other tools read them: the 16-bit PNG in millimetres through
// OpenCV, the .npy parsed by the format's own rules, the EXR's header parsed
// and its values read through OpenEXR. Texture decoding within its limits.

#include "app/images.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <opencv2/imgcodecs.hpp>

#include "tests/test_util.h"

namespace sandbox::app {
namespace {

render::Frame DepthFrame() {
  render::Frame frame;
  frame.width = 3;
  frame.height = 2;
  frame.rgb.assign(18, 0);
  const float inf = std::numeric_limits<float>::infinity();
  frame.depth_m = {1.2345f, 2.0f, inf, 0.5f, 65.0f, 70.0f};  // row 0 first
  return frame;
}

TEST(DepthFileTest, PngHoldsRoundedMillimetresAndZeroWhereNothingOrTooFar) {
  testing::TempDir dir;
  const std::string path = (dir.path() / "d.png").string();
  WriteDepthMillimetres(DepthFrame(), path);
  const cv::Mat png = cv::imread(path, cv::IMREAD_UNCHANGED);
  ASSERT_EQ(png.type(), CV_16UC1);
  ASSERT_EQ(png.cols, 3);
  ASSERT_EQ(png.rows, 2);
  EXPECT_EQ(png.at<std::uint16_t>(0, 0), 1235);  // 1.2345 m, rounded
  EXPECT_EQ(png.at<std::uint16_t>(0, 1), 2000);
  EXPECT_EQ(png.at<std::uint16_t>(0, 2), 0);  // sky
  EXPECT_EQ(png.at<std::uint16_t>(1, 0), 500);
  EXPECT_EQ(png.at<std::uint16_t>(1, 1), 65000);
  EXPECT_EQ(png.at<std::uint16_t>(1, 2), 0);  // beyond 65.535 m
}

TEST(DepthFileTest, NpyIsFloat32MetresInRowsAsNumpyReadsIt) {
  testing::TempDir dir;
  const std::string path = (dir.path() / "d.npy").string();
  const render::Frame frame = DepthFrame();
  WriteDepthNpy(frame, path);
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  std::string bytes(std::size_t(in.tellg()), '\0');
  in.seekg(0);
  in.read(bytes.data(), std::streamsize(bytes.size()));
  ASSERT_GE(bytes.size(), 10u);
  EXPECT_EQ(bytes.substr(0, 6), "\x93NUMPY");
  EXPECT_EQ(bytes[6], 1);
  EXPECT_EQ(bytes[7], 0);
  const std::size_t header_length =
      std::size_t(std::uint8_t(bytes[8])) | std::size_t(std::uint8_t(bytes[9])) << 8;
  const std::size_t data_start = 10 + header_length;
  EXPECT_EQ(data_start % 64, 0u);  // the format aligns the data
  const std::string header = bytes.substr(10, header_length);
  EXPECT_NE(header.find("'descr': '<f4'"), std::string::npos) << header;
  EXPECT_NE(header.find("'fortran_order': False"), std::string::npos) << header;
  EXPECT_NE(header.find("'shape': (2, 3)"), std::string::npos) << header;
  EXPECT_EQ(header.back(), '\n');
  ASSERT_EQ(bytes.size(), data_start + 6 * 4);
  for (std::size_t i = 0; i < 6; ++i) {
    std::uint32_t bits = 0;  // little-endian float32
    for (int b = 3; b >= 0; --b)
      bits = bits << 8 | std::uint8_t(bytes[data_start + 4 * i + std::size_t(b)]);
    float value;
    std::memcpy(&value, &bits, 4);
    EXPECT_EQ(value, frame.depth_m[i]) << i;
  }
}

TEST(DepthFileTest, ExrIsOneFloat32ChannelOfMetres) {
  testing::TempDir dir;
  const std::string path = (dir.path() / "d.exr").string();
  const render::Frame frame = DepthFrame();
  WriteDepthExr(frame, path);
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  std::string bytes(std::size_t(in.tellg()), '\0');
  in.seekg(0);
  in.read(bytes.data(), std::streamsize(bytes.size()));
  ASSERT_GE(bytes.size(), 8u);
  EXPECT_EQ(bytes.substr(0, 4), std::string("\x76\x2f\x31\x01", 4));  // OpenEXR's magic number
  // The header's channel list (attribute "channels", type "chlist"): one
  // channel, pixel type 2 = FLOAT.
  const std::size_t list = bytes.find(std::string("channels\0chlist\0", 16));
  ASSERT_NE(list, std::string::npos);
  const std::size_t first = list + 16 + 4;  // after the attribute's size
  const std::size_t name_end = bytes.find('\0', first);
  std::int32_t pixel_type = 0;
  std::memcpy(&pixel_type, &bytes[name_end + 1], 4);
  EXPECT_EQ(pixel_type, 2);
  EXPECT_EQ(bytes[name_end + 1 + 16], '\0') << "more than one channel";
  // The values, through OpenEXR (OpenCV's reader).
  const cv::Mat exr = cv::imread(path, cv::IMREAD_UNCHANGED);
  ASSERT_EQ(exr.type(), CV_32FC1);
  ASSERT_EQ(exr.cols, 3);
  ASSERT_EQ(exr.rows, 2);
  for (int i = 0; i < 6; ++i)
    EXPECT_EQ(exr.at<float>(i / 3, i % 3), frame.depth_m[std::size_t(i)]) << i;
}

// Textures: the size a PNG or JPEG states, read from its header, and
// textures that lie about it or are no files refused before decoding.
TEST(TextureTest, HeaderSizesOfRealPngAndJpeg) {
  const cv::Mat image(37, 61, CV_8UC3, cv::Scalar(10, 20, 30));
  for (const char* format : {".png", ".jpg"}) {
    std::vector<std::uint8_t> bytes;
    ASSERT_TRUE(cv::imencode(format, image, bytes));
    std::uint32_t width = 0, height = 0;
    ASSERT_TRUE(ImageHeaderSize(bytes.data(), bytes.size(), &width, &height)) << format;
    EXPECT_EQ(width, 61u) << format;
    EXPECT_EQ(height, 37u) << format;
    EXPECT_FALSE(ImageHeaderSize(bytes.data(), 10, &width, &height)) << format;
  }
  const std::uint8_t bmp[] = {'B', 'M', 0, 0};
  std::uint32_t width = 0, height = 0;
  EXPECT_FALSE(ImageHeaderSize(bmp, sizeof(bmp), &width, &height));
}

TEST(TextureTest, TexturesOverTheLimitOrNotFilesAreRefusedBeforeDecoding) {
  testing::TempDir dir;
  const cv::Mat image(300, 400, CV_8UC3, cv::Scalar(0, 128, 255));
  std::vector<std::uint8_t> png;
  ASSERT_TRUE(cv::imencode(".png", image, png));
  scene::LoadLimits limits;
  limits.max_texture_pixels = 100000;  // less than 400 x 300
  const render::TextureDecoder decode = OpenCvTextureDecoder(limits);
  scene::EmbeddedTexture embedded;
  embedded.format_hint = "png";
  embedded.width = int(png.size());
  embedded.bytes = png;
  render::RgbaImage rgba;
  EXPECT_EQ(decode(&embedded, "", &rgba),
            "400 x 300 pixels, over the limit of 100000 ([level] max_texture_pixels)");
  EXPECT_EQ(OpenCvTextureDecoder()(&embedded, "", &rgba), "");
  EXPECT_EQ(rgba.width, 400);
  EXPECT_EQ(rgba.rgba.size(), 400u * 300 * 4);
  EXPECT_EQ(rgba.rgba[2], 0);  // blue of BGR (0, 128, 255) is 0; red is 255
  EXPECT_EQ(rgba.rgba[0], 255);
  // A file that is a FIFO, and one that is missing.
  const std::string fifo = (dir.path() / "texture.png").string();
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_EQ(decode(nullptr, fifo, &rgba), "is a FIFO, not a regular file");
  EXPECT_EQ(decode(nullptr, (dir.path() / "none.png").string(), &rgba), "no such file");
}

}  // namespace
}  // namespace sandbox::app
