#include "bridge/net_fdm.h"

#include <cmath>
#include <cstring>

namespace sandbox::bridge {
namespace {

// Byte offsets in the packet (FGNetFDM v24: ">IIddd22fI4I36fI4fI3I9fIif10f").
constexpr std::size_t kLongitude = 8, kLatitude = 16, kAltitude = 24;
constexpr std::size_t kFloats = 32;  // agl, phi, theta, psi, alpha, beta, ... (22 floats)
constexpr std::size_t kCurTime = 356;
constexpr std::size_t kSurfaces = 368;  // elevator .. spoilers (10 floats)

std::uint32_t U32(const std::uint8_t* p) {
  return (std::uint32_t(p[0]) << 24) | (std::uint32_t(p[1]) << 16) | (std::uint32_t(p[2]) << 8) |
         std::uint32_t(p[3]);
}
float F32(const std::uint8_t* p) {
  const std::uint32_t bits = U32(p);
  float value;
  std::memcpy(&value, &bits, 4);
  return value;
}
double F64(const std::uint8_t* p) {
  const std::uint64_t bits = (std::uint64_t(U32(p)) << 32) | U32(p + 4);
  double value;
  std::memcpy(&value, &bits, 8);
  return value;
}
void PutU32(std::uint32_t v, std::uint8_t* p) {
  p[0] = std::uint8_t(v >> 24), p[1] = std::uint8_t(v >> 16), p[2] = std::uint8_t(v >> 8);
  p[3] = std::uint8_t(v);
}
void PutF32(float v, std::uint8_t* p) {
  std::uint32_t bits;
  std::memcpy(&bits, &v, 4);
  PutU32(bits, p);
}
void PutF64(double v, std::uint8_t* p) {
  std::uint64_t bits;
  std::memcpy(&bits, &v, 8);
  PutU32(std::uint32_t(bits >> 32), p);
  PutU32(std::uint32_t(bits), p + 4);
}

}  // namespace

std::string DecodeNetFdm(const std::uint8_t* bytes, std::size_t size, NetFdm* fdm) {
  if (size != NetFdm::kSize) {
    return "408 bytes expected, got " + std::to_string(size);
  }
  const std::uint32_t version = U32(bytes);
  if (version != NetFdm::kVersion) {
    return "version 24 expected, got " + std::to_string(version);
  }
  NetFdm out;
  out.longitude_rad = F64(bytes + kLongitude);
  out.latitude_rad = F64(bytes + kLatitude);
  out.altitude_m = F64(bytes + kAltitude);
  const std::uint8_t* f = bytes + kFloats;
  out.agl_m = F32(f), out.phi_rad = F32(f + 4), out.theta_rad = F32(f + 8),
  out.psi_rad = F32(f + 12);
  out.alpha_rad = F32(f + 16), out.beta_rad = F32(f + 20);
  out.v_north_fps = F32(f + 44), out.v_east_fps = F32(f + 48), out.v_down_fps = F32(f + 52);
  out.cur_time = U32(bytes + kCurTime);
  const std::uint8_t* s = bytes + kSurfaces;
  float* surfaces[10] = {&out.elevator,     &out.elevator_trim_tab, &out.left_flap, &out.right_flap,
                         &out.left_aileron, &out.right_aileron,     &out.rudder,    &out.nose_wheel,
                         &out.speedbrake,   &out.spoilers};
  for (int i = 0; i < 10; ++i) *surfaces[i] = F32(s + 4 * i);
  if (!std::isfinite(out.longitude_rad) || !std::isfinite(out.latitude_rad) ||
      !std::isfinite(out.altitude_m)) {
    return "non-finite position";
  }
  if (!(std::abs(out.latitude_rad) <= M_PI / 2)) return "latitude beyond +-pi/2 rad";
  if (!(std::abs(out.longitude_rad) <= 2 * M_PI)) return "longitude beyond +-2 pi rad";
  if (!(out.altitude_m >= -12000.0 && out.altitude_m <= 1e8)) {
    return "altitude outside -12 km to 1e8 m";
  }
  if (!std::isfinite(out.phi_rad) || !std::isfinite(out.theta_rad) || !std::isfinite(out.psi_rad)) {
    return "non-finite attitude";
  }
  *fdm = out;
  return "";
}

std::vector<std::uint8_t> EncodeNetFdm(const NetFdm& fdm) {
  std::vector<std::uint8_t> bytes(NetFdm::kSize, 0);
  PutU32(NetFdm::kVersion, bytes.data());
  PutF64(fdm.longitude_rad, &bytes[kLongitude]);
  PutF64(fdm.latitude_rad, &bytes[kLatitude]);
  PutF64(fdm.altitude_m, &bytes[kAltitude]);
  std::uint8_t* f = &bytes[kFloats];
  PutF32(fdm.agl_m, f), PutF32(fdm.phi_rad, f + 4), PutF32(fdm.theta_rad, f + 8);
  PutF32(fdm.psi_rad, f + 12), PutF32(fdm.alpha_rad, f + 16), PutF32(fdm.beta_rad, f + 20);
  PutF32(fdm.v_north_fps, f + 44), PutF32(fdm.v_east_fps, f + 48), PutF32(fdm.v_down_fps, f + 52);
  PutU32(fdm.cur_time, &bytes[kCurTime]);
  const float surfaces[10] = {fdm.elevator,   fdm.elevator_trim_tab, fdm.left_flap,
                              fdm.right_flap, fdm.left_aileron,      fdm.right_aileron,
                              fdm.rudder,     fdm.nose_wheel,        fdm.speedbrake,
                              fdm.spoilers};
  for (int i = 0; i < 10; ++i) PutF32(surfaces[i], &bytes[kSurfaces + 4 * std::size_t(i)]);
  return bytes;
}

}  // namespace sandbox::bridge
