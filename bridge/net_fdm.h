#pragma once
// FlightGear's native FDM packet (FGNetFDM, version 24: 408 bytes, big-endian),
// as Simulink's Aerospace Blockset FlightGear blocks send it over UDP.

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace sandbox::bridge {

struct NetFdm {
  static constexpr std::uint32_t kVersion = 24;
  static constexpr std::size_t kSize = 408;

  double longitude_rad{0.0}, latitude_rad{0.0}, altitude_m{0.0};  // geodetic, WGS84
  float agl_m{0.f};
  float phi_rad{0.f}, theta_rad{0.f}, psi_rad{0.f};  // roll, pitch, yaw (true heading), NED
  float alpha_rad{0.f}, beta_rad{0.f};
  float v_north_fps{0.f}, v_east_fps{0.f}, v_down_fps{0.f};
  std::uint32_t cur_time{0};
  // Control surfaces, normalised.
  float elevator{0.f}, elevator_trim_tab{0.f}, left_flap{0.f}, right_flap{0.f};
  float left_aileron{0.f}, right_aileron{0.f}, rudder{0.f}, nose_wheel{0.f};
  float speedbrake{0.f}, spoilers{0.f};
};

// Decodes a packet. Returns the reason it was rejected ("408 bytes expected,
// got 100", "version 24 expected, got 23", "non-finite position"), or an
// empty string with *fdm filled.
std::string DecodeNetFdm(const std::uint8_t* bytes, std::size_t size, NetFdm* fdm);

// Encodes a packet (the fields above; the rest zero), for senders and tests.
std::vector<std::uint8_t> EncodeNetFdm(const NetFdm& fdm);

}  // namespace sandbox::bridge
