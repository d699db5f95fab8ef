#pragma once
// What the instruments' configs (IMU, GNSS, air data) check and read alike.

#include <cstdint>
#include <string>

#include "scene/settings.h"

namespace sandbox::sensors {

// Throws std::invalid_argument "KEY must be zero or positive, got V".
void CheckNonNegative(const std::string& key, double value);
// The clock's settings: rate_hz zero (one sample a pose) or positive, max_gap_s positive.
void CheckInstrumentClock(double rate_hz, double max_gap_s);
// The table's `seed` (0 when absent); a negative one fails naming it.
std::uint64_t ReadSeed(scene::SettingsReader& read);

}  // namespace sandbox::sensors
