// Deferred shading on the CPU, without GL: G-buffers written here by the
// format's definition (deferred_shading.h), lit pixels against the look's
// formulas evaluated here in double, and every kernel and thread count
// against each other.

#include "sensors/render/deferred_shading.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <random>

#include "sensors/render/detail_textures.h"

namespace sandbox::render {
namespace {

// The sRGB transfer function, to a display byte.
int Srgb(double linear) {
  const double c = std::clamp(linear, 0.0, 1.0);
  return int(
      std::lround(255.0 * (c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1 / 2.4) - 0.055)));
}

// A camera at the origin looking along world +x, 60 degrees vertically;
// reversed depth from `near` to `far`, as the renderer projects.
struct Camera {
  int width, height;
  double near = 0.1, far = 2000.0, f = 1.0 / std::tan(M_PI / 6);
  Eigen::Matrix4d ClipToWorld() const {
    Eigen::Matrix4d view = Eigen::Matrix4d::Zero();  // world (x fwd, y left, z up) to GL eye
    view(0, 1) = -1, view(1, 2) = 1, view(2, 0) = -1, view(3, 3) = 1;
    Eigen::Matrix4d projection = Eigen::Matrix4d::Zero();
    projection(0, 0) = f * height / width;
    projection(1, 1) = f;
    projection(2, 2) = near / (far - near);
    projection(2, 3) = far * near / (far - near);
    projection(3, 2) = -1;
    return (projection * view).inverse();
  }
  // The world direction through pixel (x, y), row 0 at the bottom, forward component 1.
  Eigen::Vector3d Direction(int x, int y) const {
    const double ndc_x = (x + 0.5) * 2 / width - 1, ndc_y = (y + 0.5) * 2 / height - 1;
    return {1.0, -ndc_x * width / height / f, ndc_y / f};
  }
  // The reversed depth of a point `forward_m` ahead.
  float Depth(double forward_m) const {
    return float(near * (far - forward_m) / (forward_m * (far - near)));
  }
};

// A G-buffer word by the format's definition: octahedral normal in 12 + 12 bits, roughness.
std::uint32_t NormalWord(Eigen::Vector3d n, double roughness) {
  n /= std::abs(n.x()) + std::abs(n.y()) + std::abs(n.z());
  Eigen::Vector2d o = n.head<2>();
  if (n.z() < 0) {
    o = Eigen::Vector2d((1 - std::abs(n.y())) * (n.x() >= 0 ? 1 : -1),
                        (1 - std::abs(n.x())) * (n.y() >= 0 ? 1 : -1));
  }
  const auto q = [](double v) { return std::uint32_t(std::lround((0.5 * v + 0.5) * 4095)); };
  const std::uint32_t qx = q(o.x()), qy = q(o.y());
  return (qx >> 4) | ((((qx & 15) << 4) | (qy >> 8)) << 8) | ((qy & 255) << 16) |
         (std::uint32_t(std::lround(255 * roughness)) << 24);
}

// sqrt(albedo) in r, g, b and `a` as the fourth byte.
std::uint32_t AlbedoWord(const Eigen::Vector3i& sqrt_rgb, int a) {
  return std::uint32_t(sqrt_rgb.x()) | std::uint32_t(sqrt_rgb.y()) << 8 |
         std::uint32_t(sqrt_rgb.z()) << 16 | std::uint32_t(a) << 24;
}

SurfaceLayer Layer(int width, int height) {
  SurfaceLayer layer;
  layer.width = width, layer.height = height;
  const std::size_t n = std::size_t(width) * std::size_t(height);
  layer.depth.assign(n, 0.f);
  layer.albedo.assign(n, 0);
  layer.normal.assign(n, 0);
  return layer;
}

LightingFrame Frame(const Camera& camera) {
  LightingFrame frame;
  frame.clip_to_world = camera.ClipToWorld().cast<float>();
  frame.sun = Eigen::Vector3f(0.3f, -0.4f, 0.866f).normalized();
  frame.horizon = {0.5f, 0.6f, 0.8f};
  frame.zenith = {0.2f, 0.3f, 0.7f};
  frame.sky_horizon_display = {0.62f, 0.76f, 0.92f};
  frame.sky_zenith_display = {0.36f, 0.5f, 0.76f};
  frame.materials = false;
  return frame;
}

const std::uint8_t* At(const std::vector<std::uint8_t>& rgba, int width, int x, int y) {
  return &rgba[4 * (std::size_t(y) * std::size_t(width) + std::size_t(x))];
}

TEST(DeferredShadingTest, EncodeSrgbIsTheTransferFunction) {
  EXPECT_EQ(EncodeSrgb(0.f), 0);
  EXPECT_EQ(EncodeSrgb(1.f), 255);
  EXPECT_EQ(EncodeSrgb(2.f), 255);
  EXPECT_EQ(EncodeSrgb(0.5f), 188);     // 255 (1.055 0.5^(1/2.4) - 0.055) = 187.5
  EXPECT_EQ(EncodeSrgb(0.002f), 7);     // linear segment: 255 12.92 0.002 = 6.6
  EXPECT_EQ(EncodeSrgb(0.214f), 127);   // 127.49
  EXPECT_EQ(EncodeSrgb(0.2159f), 128);  // 128.01
}

TEST(DeferredShadingTest, WhereNothingWasDrawnTheSkyShowsItsGradientAndTheSunsDisc) {
  const Camera camera{61, 47};  // odd sizes: a middle row and column, partial vectors
  LightingFrame frame = Frame(camera);
  frame.sun = Eigen::Vector3f::UnitX();  // at the middle pixel
  const SurfaceLayer nothing = Layer(camera.width, camera.height);
  DeferredShader shader(2);
  std::vector<std::uint8_t> rgb;
  shader.Shade(frame, DetailTextures(), nothing, nullptr, &rgb);
  for (int y : {0, 10, 23, 46}) {
    for (int x : {0, 5, 60}) {
      const Eigen::Vector3d d = camera.Direction(x, y).normalized();
      const double up = std::pow(std::max(d.z(), 0.0), 0.6);
      for (int c = 0; c < 3; ++c) {
        const double expected = frame.sky_horizon_display[c] +
                                (frame.sky_zenith_display[c] - frame.sky_horizon_display[c]) * up;
        EXPECT_NEAR(At(rgb, camera.width, x, y)[c], 255 * expected, 0.6) << x << " " << y;
      }
    }
  }
  const std::uint8_t* sun = At(rgb, camera.width, 30, 23);
  EXPECT_NEAR(sun[0], 255, 1);
  EXPECT_NEAR(sun[1], 250, 1);
  EXPECT_NEAR(sun[2], 230, 1);
}

// A surface everywhere 40 m ahead, facing up; the sun's light by Lambert's
// cosine and the sky's light from above (deferred_kernel.cc's Lit), haze by
// distance between fog start and end.
TEST(DeferredShadingTest, LitSurfacesFollowLambertSkyLightAndHaze) {
  const Camera camera{40, 30};
  LightingFrame frame = Frame(camera);
  frame.fog = {30.f, 90.f};
  SurfaceLayer layer = Layer(camera.width, camera.height);
  const Eigen::Vector3i sqrt_albedo(200, 150, 60);
  std::fill(layer.depth.begin(), layer.depth.end(), camera.Depth(40.0));
  std::fill(layer.albedo.begin(), layer.albedo.end(), AlbedoWord(sqrt_albedo, 0));
  std::fill(layer.normal.begin(), layer.normal.end(), NormalWord(Eigen::Vector3d::UnitZ(), 1.0));
  DeferredShader shader(1);
  std::vector<std::uint8_t> rgb;
  shader.Shade(frame, DetailTextures(), layer, nullptr, &rgb);
  const double light = 0.75 * frame.sun.z() + 0.25;
  for (int y : {0, 14, 29}) {
    for (int x : {0, 20, 39}) {
      const double distance = 40.0 * camera.Direction(x, y).norm();
      const double haze = std::clamp((distance - 30.0) / 60.0, 0.0, 1.0);
      for (int c = 0; c < 3; ++c) {
        const double albedo = std::pow(sqrt_albedo[c] / 255.0, 2);
        const double expected = albedo * light + (frame.horizon[c] - albedo * light) * haze;
        EXPECT_NEAR(At(rgb, camera.width, x, y)[c], Srgb(expected), 1) << x << " " << y << " " << c;
      }
    }
  }
}

TEST(DeferredShadingTest, ATranslucentSurfaceIsBlendedOverTheOpaqueOneByItsAlpha) {
  const Camera camera{16, 8};
  const LightingFrame frame = Frame(camera);
  SurfaceLayer opaque = Layer(camera.width, camera.height), glass = opaque;
  std::fill(opaque.depth.begin(), opaque.depth.end(), camera.Depth(50.0));
  std::fill(opaque.albedo.begin(), opaque.albedo.end(), AlbedoWord({230, 40, 40}, 0));
  std::fill(opaque.normal.begin(), opaque.normal.end(), NormalWord(Eigen::Vector3d::UnitZ(), 1.0));
  // Glass in the left half only, nearer; the translucent word: 8 + 8 bit normal, roughness, code.
  for (int y = 0; y < camera.height; ++y) {
    for (int x = 0; x < camera.width / 2; ++x) {
      const std::size_t i = std::size_t(y * camera.width + x);
      glass.depth[i] = camera.Depth(20.0);
      glass.albedo[i] = AlbedoWord({40, 40, 230}, 64);                           // alpha 64 / 255
      glass.normal[i] = 128u | 128u << 8 | 255u << 16 | std::uint32_t(0) << 24;  // up, rough
    }
  }
  DeferredShader shader(1);
  std::vector<std::uint8_t> under, over;
  shader.Shade(frame, DetailTextures(), opaque, nullptr, &under);
  shader.Shade(frame, DetailTextures(), opaque, &glass, &over);
  const double light = 0.75 * frame.sun.z() + 0.25, alpha = 64 / 255.0;
  for (int y = 0; y < camera.height; ++y) {
    for (int x = 0; x < camera.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        const int below = At(under, camera.width, x, y)[c];
        if (x >= camera.width / 2) {
          EXPECT_EQ(At(over, camera.width, x, y)[c], below);
          continue;
        }
        const double glass_albedo = std::pow((c == 2 ? 230 : 40) / 255.0, 2);
        const double expected = Srgb(glass_albedo * light) * alpha + below * (1 - alpha);
        EXPECT_NEAR(At(over, camera.width, x, y)[c], expected, 1.0) << x << " " << y << " " << c;
      }
    }
  }
}

// A G-buffer of every kind (ground with detail, water, prelit, shiny metal,
// sky), shadows in two cascades and a moving casters' map, and a translucent
// layer: each kernel and thread count gives the same bytes, and so does the
// edge filter.
TEST(DeferredShadingTest, EveryKernelAndThreadCountGivesTheSameBytes) {
  const Camera camera{203, 77};
  LightingFrame frame = Frame(camera);
  frame.materials = true;
  frame.fog = {50.f, 400.f};
  frame.water_level = 1.f;
  frame.ground = {Eigen::Vector3f(0.1f, 0.2f, 0.05f), Eigen::Vector3f(0.2f, 0.2f, 0.18f),
                  Eigen::Vector3f(0.9f, 0.9f, 0.92f), Eigen::Vector3f(0.5f, 0.45f, 0.3f)};
  frame.lod_offset_per_m = 0.002f;
  std::mt19937 random(7);
  std::uniform_real_distribution<float> unit(0.f, 1.f);
  constexpr int kPx = 64;
  std::vector<float> maps(2 * kPx * kPx);
  for (float& d : maps) d = unit(random);
  for (int c = 0; c < 2; ++c) {
    Eigen::Matrix4f clip = Eigen::Matrix4f::Identity() / float(30 * (c + 1));
    clip(2, 2) = -0.01f, clip(2, 3) = 0.5f, clip(3, 3) = 1.f;
    frame.cascades.push_back(
        {clip, 40.f * float(c + 1), 0.5f, kPx, &maps[std::size_t(c) * kPx * kPx]});
  }
  std::vector<float> moving(kPx * kPx);
  for (float& d : moving)
    d = unit(random) < 0.7f ? std::numeric_limits<float>::infinity() : unit(random);
  Eigen::Matrix4f moving_clip = Eigen::Matrix4f::Identity() / 20.f;
  moving_clip(2, 2) = -0.05f, moving_clip(2, 3) = 0.5f, moving_clip(3, 3) = 1.f;
  frame.moving_casters = {moving_clip, 0.f, 0.1f, kPx, moving.data()};
  SurfaceLayer opaque = Layer(camera.width, camera.height), translucent = opaque;
  for (std::size_t i = 0; i < opaque.depth.size(); ++i) {
    const bool sky = unit(random) < 0.1f;
    opaque.depth[i] = sky ? 0.f : camera.Depth(1.0 + 300.0 * unit(random));
    const Eigen::Vector3d n =
        Eigen::Vector3d(unit(random) - 0.5, unit(random) - 0.5, unit(random) - 0.3);
    const int kind = int(unit(random) * 4);  // lit, ground, ground on imagery, prelit
    const int metal = int(unit(random) * 32);
    opaque.albedo[i] =
        AlbedoWord({int(unit(random) * 255), int(unit(random) * 255), int(unit(random) * 255)},
                   kind + 8 * metal);
    opaque.normal[i] = NormalWord(n.normalized(), unit(random));
    translucent.depth[i] = unit(random) < 0.4f ? camera.Depth(0.5 + 50 * unit(random)) : 0.f;
    translucent.albedo[i] = AlbedoWord({90, 120, 140}, int(unit(random) * 255));
    const int code = unit(random) < 0.5f ? int(SurfaceKind::kWater) : int(SurfaceKind::kLit);
    translucent.normal[i] = std::uint32_t(unit(random) * 255) |
                            std::uint32_t(unit(random) * 255) << 8 |
                            std::uint32_t(unit(random) * 255) << 16 | std::uint32_t(code) << 24;
  }
  const DetailTextures detail(MakeDetailTextures(64), 64, kNumDetailLayers);
  std::vector<std::uint8_t> reference, reference_filtered;
  for (const std::string& kernel : DeferredShader::Kernels()) {
    for (int threads : {1, 3}) {
      DeferredShader shader(threads, kernel);
      EXPECT_EQ(shader.kernel(), kernel);
      std::vector<std::uint8_t> rgb, filtered;
      shader.Shade(frame, detail, opaque, &translucent, &rgb);
      shader.FilterEdges(rgb, camera.width, camera.height, &filtered);
      if (reference.empty()) {
        reference = rgb, reference_filtered = filtered;
        continue;
      }
      EXPECT_EQ(rgb, reference) << kernel << ", " << threads << " threads";
      EXPECT_EQ(filtered, reference_filtered) << kernel << ", " << threads << " threads";
    }
  }
  EXPECT_NE(reference, reference_filtered);  // the random image has edges
}

TEST(DeferredShadingTest, AnUnknownKernelIsRefusedByName) {
  try {
    DeferredShader shader(1, "avx9000");
    FAIL() << "no throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'avx9000'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("sse2"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace sandbox::render
