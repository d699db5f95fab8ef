// Sends FlightGear net_fdm v24 packets over UDP, as Simulink's Aerospace
// Blockset FlightGear blocks do: a sandbox robot with net_fdm_port set in its
// [robot.bridge] follows. Flies a 120 m circle around a geodetic origin, or
// hovers at one point with --hover.
//
//   send_net_fdm [--port P] [--rate HZ] [--duration S] [--origin LAT,LON,ALT] [--hover]

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <thread>

#include "bridge/net_fdm.h"

int main(int argc, char** argv) {
  int port = 5505;
  double rate_hz = 100.0, duration_s = 10.0, lat0 = 47.0, lon0 = 8.0, alt0 = 500.0;
  bool hover = false;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--hover"))
      hover = true;
    else if (i + 1 < argc && !std::strcmp(argv[i], "--port"))
      port = std::atoi(argv[++i]);
    else if (i + 1 < argc && !std::strcmp(argv[i], "--rate"))
      rate_hz = std::atof(argv[++i]);
    else if (i + 1 < argc && !std::strcmp(argv[i], "--duration"))
      duration_s = std::atof(argv[++i]);
    else if (i + 1 < argc && !std::strcmp(argv[i], "--origin")) {
      std::sscanf(argv[++i], "%lf,%lf,%lf", &lat0, &lon0, &alt0);
    } else {
      std::fprintf(stderr,
                   "usage: send_net_fdm [--port P] [--rate HZ] [--duration S] "
                   "[--origin LAT,LON,ALT] [--hover]\n");
      return 2;
    }
  }
  const int s = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(static_cast<std::uint16_t>(port));
  inet_pton(AF_INET, "127.0.0.1", &to.sin_addr);
  const double deg = M_PI / 180.0, earth = 6371000.0;
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  auto next = start;
  int sent = 0;
  for (;;) {
    const double t = std::chrono::duration<double>(Clock::now() - start).count();
    if (t >= duration_s) break;
    sandbox::bridge::NetFdm fdm;
    // Hover: one arc second north of the origin, 100 m above it, heading east.
    double north = 0.0, east = 0.0, heading = M_PI / 2;
    if (!hover) {
      const double a = 15.0 / 120.0 * t;
      north = 120.0 * std::sin(a), east = 120.0 * std::cos(a),
      heading = -a;  // clockwise from above
    }
    fdm.latitude_rad = (lat0 + (hover ? 1.0 / 3600.0 : north / earth / deg)) * deg;
    fdm.longitude_rad = (lon0 + east / (earth * std::cos(lat0 * deg)) / deg) * deg;
    fdm.altitude_m = alt0 + 100.0;
    fdm.psi_rad = float(heading);
    fdm.elevator = float(0.3 * std::sin(2.0 * t));
    const auto bytes = sandbox::bridge::EncodeNetFdm(fdm);
    ::sendto(s, bytes.data(), bytes.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof(to));
    ++sent;
    next +=
        std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / rate_hz));
    std::this_thread::sleep_until(next);
  }
  ::close(s);
  std::printf("send_net_fdm: %d packets to 127.0.0.1:%d\n", sent, port);
  return 0;
}
