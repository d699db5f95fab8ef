#include "sensors/instrument_settings.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace sandbox::sensors {

void CheckNonNegative(const std::string& key, double value) {
  if (!(std::isfinite(value) && value >= 0.0)) {
    throw std::invalid_argument(key + " must be zero or positive, got " +
                                (std::ostringstream() << value).str());
  }
}

void CheckInstrumentClock(double rate_hz, double max_gap_s) {
  if (!(std::isfinite(rate_hz) && rate_hz >= 0.0)) {
    throw std::invalid_argument("rate_hz must be positive");
  }
  if (!(std::isfinite(max_gap_s) && max_gap_s > 0.0)) {
    throw std::invalid_argument("max_gap_s must be positive");
  }
}

std::uint64_t ReadSeed(scene::SettingsReader& read) {
  const int seed = read.Whole("seed", 0);
  if (seed < 0) read.Fail("seed", "'seed' must be zero or positive");
  return std::uint64_t(seed);
}

}  // namespace sandbox::sensors
