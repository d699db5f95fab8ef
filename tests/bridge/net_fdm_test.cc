// FlightGear net_fdm packets: known bytes, round trips, bad packets.

#include "bridge/net_fdm.h"

#include <gtest/gtest.h>

#include <cmath>

namespace sandbox::bridge {
namespace {

TEST(NetFdmTest, ReadsBigEndianFieldsAtTheirOffsets) {
  std::vector<std::uint8_t> bytes(408, 0);
  bytes[3] = 24;  // version
  // latitude = 1.0 (double, big-endian 3FF0000000000000) at byte 16
  bytes[16] = 0x3F, bytes[17] = 0xF0;
  // psi = 2.0f (40000000) at 32 + 12; elevator = -0.5f (BF000000) at 368
  bytes[44] = 0x40;
  bytes[368] = 0xBF;
  NetFdm fdm;
  ASSERT_EQ(DecodeNetFdm(bytes.data(), bytes.size(), &fdm), "");
  EXPECT_DOUBLE_EQ(fdm.latitude_rad, 1.0);
  EXPECT_FLOAT_EQ(fdm.psi_rad, 2.0f);
  EXPECT_FLOAT_EQ(fdm.elevator, -0.5f);
  EXPECT_DOUBLE_EQ(fdm.longitude_rad, 0.0);
}

TEST(NetFdmTest, RoundTrip) {
  NetFdm fdm;
  fdm.latitude_rad = 0.82, fdm.longitude_rad = 0.14, fdm.altitude_m = 1200.5;
  fdm.phi_rad = 0.1f, fdm.theta_rad = -0.05f, fdm.psi_rad = 1.5f;
  fdm.left_aileron = 0.25f, fdm.rudder = -0.75f, fdm.cur_time = 123456;
  const std::vector<std::uint8_t> bytes = EncodeNetFdm(fdm);
  ASSERT_EQ(bytes.size(), 408u);
  NetFdm back;
  ASSERT_EQ(DecodeNetFdm(bytes.data(), bytes.size(), &back), "");
  EXPECT_DOUBLE_EQ(back.altitude_m, 1200.5);
  EXPECT_FLOAT_EQ(back.theta_rad, -0.05f);
  EXPECT_FLOAT_EQ(back.left_aileron, 0.25f);
  EXPECT_FLOAT_EQ(back.rudder, -0.75f);
  EXPECT_EQ(back.cur_time, 123456u);
}

TEST(NetFdmTest, BadPacketsAreRejectedWithTheReason) {
  NetFdm fdm;
  fdm.altitude_m = 7.0;
  NetFdm kept = fdm;
  std::vector<std::uint8_t> bytes = EncodeNetFdm(NetFdm{});
  EXPECT_EQ(DecodeNetFdm(bytes.data(), 100, &kept), "408 bytes expected, got 100");
  bytes[3] = 23;
  EXPECT_EQ(DecodeNetFdm(bytes.data(), bytes.size(), &kept), "version 24 expected, got 23");
  NetFdm nan;
  nan.altitude_m = std::nan("");
  bytes = EncodeNetFdm(nan);
  EXPECT_EQ(DecodeNetFdm(bytes.data(), bytes.size(), &kept), "non-finite position");
  EXPECT_DOUBLE_EQ(kept.altitude_m, 7.0);  // untouched
  // Finite but no place on Earth.
  NetFdm far = NetFdm{};
  far.latitude_rad = 1e300;
  bytes = EncodeNetFdm(far);
  EXPECT_EQ(DecodeNetFdm(bytes.data(), bytes.size(), &kept), "latitude beyond +-pi/2 rad");
  far = NetFdm{};
  far.longitude_rad = -7.0;
  bytes = EncodeNetFdm(far);
  EXPECT_EQ(DecodeNetFdm(bytes.data(), bytes.size(), &kept), "longitude beyond +-2 pi rad");
  for (const double altitude_m : {1e308, -20000.0}) {
    far = NetFdm{};
    far.altitude_m = altitude_m;
    bytes = EncodeNetFdm(far);
    EXPECT_EQ(DecodeNetFdm(bytes.data(), bytes.size(), &kept), "altitude outside -12 km to 1e8 m");
  }
  far = NetFdm{};
  far.latitude_rad = M_PI / 2, far.altitude_m = 35786e3;  // the pole; geostationary height
  bytes = EncodeNetFdm(far);
  EXPECT_EQ(DecodeNetFdm(bytes.data(), bytes.size(), &kept), "");
  EXPECT_DOUBLE_EQ(kept.altitude_m, 35786e3);
}

}  // namespace
}  // namespace sandbox::bridge
