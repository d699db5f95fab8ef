// Level files that lie or are not files: refused with one clear message
// before they are opened or before what they claim is allocated, and the
// limits a manifest sets named in the message.

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdint>
#include <string>

#include "scene/level.h"
#include "scene/manifest.h"
#include "tests/scene/load_error.h"
#include "tests/scene/obj_text.h"
#include "tests/test_util.h"

namespace sandbox::scene {
namespace {

using testing::LoadError;
using testing::TempDir;

// PNG's CRC-32 (ISO-HDLC), bit by bit.
std::uint32_t Crc32(const std::string& bytes) {
  std::uint32_t crc = 0xffffffffu;
  for (const char c : bytes) {
    crc ^= std::uint8_t(c);
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

std::string BigEndian32(std::uint32_t v) {
  return {char(v >> 24), char(v >> 16), char(v >> 8), char(v)};
}

std::string Chunk(const std::string& type, const std::string& data) {
  return BigEndian32(std::uint32_t(data.size())) + type + data + BigEndian32(Crc32(type + data));
}

// A PNG whose header says `width` x `height` 8-bit grey pixels, followed by
// a few bytes of image data (far too few: the header lies).
std::string LyingPng(std::uint32_t width, std::uint32_t height) {
  const std::string ihdr =
      BigEndian32(width) + BigEndian32(height) + std::string("\x08\x00\x00\x00\x00", 5);
  return std::string("\x89PNG\r\n\x1a\n", 8) + Chunk("IHDR", ihdr) +
         Chunk("IDAT", std::string("\x78\x9c\x63\x00\x00\x00\x01\x00\x01", 9)) + Chunk("IEND", "");
}

std::string HeightmapManifest(const std::string& file, const std::string& level_table = "") {
  return level_table + "[[actor]]\nname = \"land\"\nheightmap = \"" + file +
         "\"\nsize = [100, 100, 10]\n";
}

TEST(HostileFilesTest, FifosAndDevicesAreRefusedBeforeTheyAreOpened) {
  TempDir dir;
  // Each would block (a FIFO without a writer) or never end (/dev/zero).
  for (const char* name : {"level.toml", "mesh.obj", "land.png"}) {
    ASSERT_EQ(mkfifo((dir.path() / name).c_str(), 0600), 0);
  }
  const std::string fifo_level = (dir.path() / "level.toml").string();
  EXPECT_EQ(LoadError(fifo_level), fifo_level + ": is a FIFO, not a regular file");
  const std::string fifo_mesh = (dir.path() / "mesh.obj").string();
  EXPECT_EQ(LoadError(fifo_mesh), fifo_mesh + ": is a FIFO, not a regular file");
  EXPECT_EQ(LoadError("/dev/zero"), "/dev/zero: is a device, not a regular file");
  // Named by a manifest: the manifest's line and the actor, then the file.
  const auto actor = dir.Write("actor.toml", "[[actor]]\nname = \"m\"\nfile = \"mesh.obj\"\n");
  EXPECT_EQ(LoadError(actor),
            actor.string() + ":1: actor 'm': " + fifo_mesh + ": is a FIFO, not a regular file");
  const auto land = dir.Write("land.toml", HeightmapManifest("land.png"));
  EXPECT_NE(LoadError(land).find("land.png: is a FIFO, not a regular file"), std::string::npos)
      << LoadError(land);
  const auto robot = dir.Write("robot.toml", "[[robot]]\nname = \"r\"\nfile = \"mesh.obj\"\n");
  EXPECT_NE(LoadError(robot).find("mesh.obj: is a FIFO, not a regular file"), std::string::npos)
      << LoadError(robot);
}

TEST(HostileFilesTest, AHeightmapHeaderClaimingAHugeGridIsRefusedBeforeDecoding) {
  TempDir dir;
  dir.Write("huge.png", LyingPng(20000, 20000));
  const auto level = dir.Write("level.toml", HeightmapManifest("huge.png"));
  const std::string error = LoadError(level);
  EXPECT_NE(error.find("huge.png: a grid of 20000 x 20000 samples, over the limit of 16777216 "
                       "([level] max_heightmap_samples in a level manifest)"),
            std::string::npos)
      << error;
  // The same for a PGM header.
  dir.Write("huge.pgm", "P5\n30000 30000\n255\n" + std::string(100, '\0'));
  const auto pgm_level = dir.Write("pgm.toml", HeightmapManifest("huge.pgm"));
  EXPECT_NE(LoadError(pgm_level).find("a grid of 30000 x 30000 samples, over the limit"),
            std::string::npos)
      << LoadError(pgm_level);
  // A manifest may raise the limit; then the lie shows as a broken image.
  dir.Write("big.png", LyingPng(5000, 5000));
  const auto raised = dir.Write(
      "raised.toml", HeightmapManifest("big.png", "[level]\nmax_heightmap_samples = 30000000\n"));
  EXPECT_NE(LoadError(raised).find("big.png: cannot decode PNG"), std::string::npos)
      << LoadError(raised);
}

TEST(HostileFilesTest, AGlbWhoseHeaderLiesIsRefused) {
  TempDir dir;
  // "glTF", version 2, total length 3 GB; a JSON chunk of 2 GB.
  const std::string lying_total = std::string("glTF\x02\0\0\0", 8) +
                                  std::string("\x00\x00\x00\xc0", 4) +
                                  std::string("\x00\x00\x00\x80JSON{}", 10);
  const auto total = dir.Write("total.glb", lying_total);
  EXPECT_EQ(LoadError(total),
            total.string() + ": its header says 3221225472 bytes, the file has 22");
  std::string lying_chunk = std::string("glTF\x02\0\0\0", 8) + std::string("\x16\0\0\0", 4) +
                            std::string("\x00\x00\x00\x80JSON{}", 10);
  const auto chunk = dir.Write("chunk.glb", lying_chunk);
  EXPECT_EQ(LoadError(chunk), chunk.string() +
                                  ": a chunk at byte 12 says 2147483648 bytes, past the end of "
                                  "the file");
}

TEST(HostileFilesTest, ManifestNumbersBeyondTwoToThe53AreAnErrorNotZero) {
  TempDir dir;
  dir.Write("box.obj", testing::ObjBox("box", 1, 1, 1));
  const auto level = dir.Write("level.toml",
                               "[[actor]]\nname = \"box\"\nfile = \"box.obj\"\n"
                               "position = [9007199254740993, 0, 0]\n");
  EXPECT_EQ(LoadError(level), level.string() +
                                  ":4: actor 'box': 'position' is 9007199254740993, beyond 2^53 "
                                  "(numbers that large lose their last digits)");
  // 2^53 itself is exact.
  const auto exact = dir.Write("exact.toml",
                               "[[actor]]\nname = \"box\"\nfile = \"box.obj\"\n"
                               "position = [9007199254740992, 0, 0]\n");
  EXPECT_EQ(LoadLevel(exact).actors.at(0).X_WA.translation().x(), 9007199254740992.0);
}

TEST(HostileFilesTest, ALevelOverItsTriangleOrFileLimitNamesTheKey) {
  TempDir dir;
  dir.Write("box.obj", testing::ObjBox("box", 1, 1, 1));  // 12 triangles
  const auto small =
      dir.Write("small.toml",
                "[level]\nmax_triangles = 20\n[[actor]]\nname = \"a\"\nfile = \"box.obj\"\n"
                "[[actor]]\nname = \"b\"\nfile = \"box.obj\"\n");
  EXPECT_EQ(LoadError(small), (dir.path() / "box.obj").string() +
                                  ": the level has 24 triangles, over the limit of 20 ([level] "
                                  "max_triangles in a level manifest)");
  const auto files = dir.Write(
      "files.toml", "[level]\nmax_file_mb = 0\n[[actor]]\nname = \"a\"\nfile = \"box.obj\"\n");
  EXPECT_NE(LoadError(files).find("box.obj: 1 MB, over the limit of 0 ([level] max_file_mb"),
            std::string::npos)
      << LoadError(files);
  const auto typo = dir.Write("typo.toml", "[level]\nmax_triangels = 20\n");
  EXPECT_EQ(LoadError(typo), typo.string() + ":2: [level]: unknown key 'max_triangels'");
  const auto negative = dir.Write("negative.toml", "[level]\nmax_triangles = -1\n");
  EXPECT_EQ(LoadError(negative),
            negative.string() +
                ":2: [level]: 'max_triangles' must be a whole number from 0 to 1125899906842624");
}

TEST(HostileFilesTest, APlyFaceWithoutIndicesIsDroppedNotAnAssimpAbort) {
  TempDir dir;
  // Binary PLY: 3 vertices, a face of 0 indices (assimp's triangulation
  // asserts on it and aborts) and a good triangle.
  std::string ply =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 2\n"
      "property list uchar int vertex_indices\nend_header\n";
  const float vertices[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  ply.append(reinterpret_cast<const char*>(vertices), sizeof(vertices));
  ply += '\0';  // the empty face
  const std::int32_t triangle[3] = {0, 1, 2};
  ply += '\3';
  ply.append(reinterpret_cast<const char*>(triangle), sizeof(triangle));
  const Level level = LoadLevel(dir.Write("empty_face.ply", ply));
  EXPECT_EQ(level.num_triangles(), 1u);
  ASSERT_FALSE(level.warnings.empty());
  EXPECT_NE(level.warnings[0].find("dropped 1 faces"), std::string::npos) << level.warnings[0];
}

}  // namespace
}  // namespace sandbox::scene
