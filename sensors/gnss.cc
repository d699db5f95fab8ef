#include "sensors/gnss.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "sensors/instrument_settings.h"

namespace sandbox::sensors {
namespace {

// World from the local east-north-up frame at a geodetic point.
Eigen::Matrix3d WorldFromLocal(const scene::LocalTangentPlane& frame, const GnssFix& at) {
  return frame.R_WorldEcef() * scene::EcefFromEnu(at.latitude_deg, at.longitude_deg);
}

}  // namespace

void GnssConfig::ValidateOrThrow() const {
  CheckInstrumentClock(rate_hz, max_gap_s);
  CheckNonNegative("latency_s", latency_s);
  CheckNonNegative("horizontal_sigma_m", horizontal_sigma_m);
  CheckNonNegative("vertical_sigma_m", vertical_sigma_m);
  CheckNonNegative("velocity_sigma_m_s", velocity_sigma_m_s);
}

GnssConfig GnssConfig::Read(scene::SettingsReader& read) {
  GnssConfig config;
  config.latency_s = read.Number("latency_s", config.latency_s);
  config.horizontal_sigma_m = read.Number("horizontal_sigma_m", config.horizontal_sigma_m);
  config.vertical_sigma_m = read.Number("vertical_sigma_m", config.vertical_sigma_m);
  config.velocity_sigma_m_s = read.Number("velocity_sigma_m_s", config.velocity_sigma_m_s);
  config.seed = ReadSeed(read);
  config.max_gap_s = read.Number("max_gap_s", config.max_gap_s);
  return config;
}

std::string GnssConfig::Summary() const {
  std::ostringstream out;
  out << "latency " << latency_s << " s, ";
  if (horizontal_sigma_m > 0.0 || vertical_sigma_m > 0.0 || velocity_sigma_m_s > 0.0) {
    out << "noisy (seed " << seed << ")";
  } else {
    out << "noise off";
  }
  return out.str();
}

GnssFix TrueFix(const scene::LocalTangentPlane& frame, const Eigen::Vector3d& p_W,
                const Eigen::Vector3d& v_W) {
  const scene::GeodeticPoint point = frame.ToGeodetic(p_W);
  GnssFix fix;
  fix.latitude_deg = point.latitude_deg;
  fix.longitude_deg = point.longitude_deg;
  fix.height_m = point.height_m;
  const Eigen::Vector3d v_enu = WorldFromLocal(frame, fix).transpose() * v_W;
  fix.velocity_ned = Eigen::Vector3d(v_enu.y(), v_enu.x(), -v_enu.z());
  return fix;
}

Gnss::Gnss(const GnssConfig& config)
    : config_(config), clock_(config.rate_hz, config.max_gap_s), random_(config.seed) {
  config_.ValidateOrThrow();
}

void Gnss::Run(const SensorContext& at, GnssFixes* out) {
  out->fixes.clear();
  if (at.geodetic == nullptr) return;
  for (const std::int64_t utime : clock_.Add(at.pose_utime, at.X_WS)) {
    const FrameMotion motion = clock_.At(utime);
    Eigen::Vector3d p_W = motion.p_W, v_W = motion.v_W;
    if (config_.horizontal_sigma_m > 0.0 || config_.vertical_sigma_m > 0.0 ||
        config_.velocity_sigma_m_s > 0.0) {
      // Noise in the local east-north-up frame at the point.
      const Eigen::Matrix3d R_WL = WorldFromLocal(*at.geodetic, TrueFix(*at.geodetic, p_W, v_W));
      const Eigen::Vector3d dp(config_.horizontal_sigma_m * normal_(random_),
                               config_.horizontal_sigma_m * normal_(random_),
                               config_.vertical_sigma_m * normal_(random_));
      Eigen::Vector3d dv;
      for (int k = 0; k < 3; ++k) dv[k] = config_.velocity_sigma_m_s * normal_(random_);
      p_W += R_WL * dp;
      v_W += R_WL * dv;
    }
    GnssFix fix = TrueFix(*at.geodetic, p_W, v_W);
    fix.utime = utime;
    pending_.push_back(fix);
  }
  if (!pending_.empty() && at.pose_utime < pending_.back().utime) pending_.clear();  // went back
  // Released once their latency has passed on the poses' clock.
  const double latency_us = config_.latency_s * 1e6;
  while (!pending_.empty() && double(at.pose_utime - pending_.front().utime) >= latency_us - 0.5) {
    out->fixes.push_back(pending_.front());
    pending_.pop_front();
  }
}

}  // namespace sandbox::sensors
