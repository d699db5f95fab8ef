#include "sensors/sensor.h"

#include <sstream>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <vector>

#include "scene/settings.h"

namespace sandbox::sensors {
namespace {

constexpr auto kAlternatives = std::make_index_sequence<kSensorKinds.size()>();

// The lists agree: kind i is row i and class i.
template <std::size_t... I>
constexpr bool KindsInOrder(std::index_sequence<I...>) {
  return kSensorKinds.size() == std::variant_size_v<SensorClasses::Any> &&
         ((kSensorKinds[I].kind == SensorKind(I) &&
           kSensorKinds[I].type == std::variant_alternative_t<I, SensorClasses::Any>::kType) &&
          ...);
}
static_assert(KindsInOrder(kAlternatives),
              "SensorKind, SensorClasses and kSensorKinds must list the kinds in one order");

// The config of alternative I, read from the table.
template <std::size_t I>
SensorConfig ReadAlternative(scene::SettingsReader& read) {
  return SensorConfig(std::in_place_index<I>,
                      std::variant_alternative_t<I, SensorConfig>::Read(read));
}
template <std::size_t... I>
SensorConfig ReadConfig(SensorKind kind, scene::SettingsReader& read, std::index_sequence<I...>) {
  static constexpr SensorConfig (*kRead[])(scene::SettingsReader&) = {&ReadAlternative<I>...};
  return kRead[std::size_t(kind)](read);
}

// The class of alternative I, made from its config.
template <std::size_t I>
SensorClasses::Any MakeAlternative(const SensorConfig& config) {
  return SensorClasses::Any(std::in_place_index<I>, std::get<I>(config));
}
template <std::size_t... I>
SensorClasses::Any MakeClass(const SensorConfig& config, std::index_sequence<I...>) {
  static constexpr SensorClasses::Any (*kMake[])(const SensorConfig&) = {&MakeAlternative<I>...};
  return kMake[config.index()](config);
}

// A class's history_s(), or 0 when it has none.
template <typename Class, typename = void>
struct HistoryOf {
  static double Of(const Class&) { return 0.0; }
};
template <typename Class>
struct HistoryOf<Class, std::void_t<decltype(std::declval<const Class&>().history_s())>> {
  static double Of(const Class& sensor) { return sensor.history_s(); }
};

// A config with rate_hz samples on its own clock.
template <typename Config, typename = void>
struct OwnRate : std::false_type {};
template <typename Config>
struct OwnRate<Config, std::void_t<decltype(Config::rate_hz)>> : std::true_type {};

}  // namespace

const SensorKindInfo& Info(SensorKind kind) { return kSensorKinds[std::size_t(kind)]; }

SensorKind ParseSensorKind(const scene::SensorSpec& spec) {
  std::vector<std::string_view> types;
  for (const SensorKindInfo& info : kSensorKinds) {
    if (info.type == spec.type) return info.kind;
    types.push_back(info.type);
  }
  throw scene::LevelError(spec.settings.Where("type") + "'type' must be " +
                          scene::ChoiceList(types) + ", got '" + spec.type + "'");
}

std::string OutputChannel(const scene::SensorSpec& spec) {
  if (!spec.channel.empty()) return spec.channel;
  return std::string(Info(ParseSensorKind(spec)).channel);
}

std::string MountedSensor::Describe() const {
  std::ostringstream out;
  out << spec.type << " " << std::visit([](const auto& c) { return c.Summary(); }, config) << " on "
      << (spec.mount.empty() ? "body" : spec.mount);
  if (spec.rate_hz > 0.0) out << " at " << spec.rate_hz << " Hz";
  return out.str();
}

bool MountedSensor::RunsEveryTick() const {
  return std::visit([](const auto& c) { return OwnRate<std::decay_t<decltype(c)>>::value; },
                    config);
}

std::vector<MountedSensor> MakeRobotSensors(const scene::Level& level) {
  std::vector<MountedSensor> sensors;
  for (std::size_t r = 0; r < level.robots.size(); ++r) {
    for (const scene::SensorSpec& spec : level.robots[r].sensors) {
      MountedSensor sensor;
      sensor.spec = spec;
      sensor.kind = ParseSensorKind(spec);
      sensor.robot = static_cast<int>(r);
      sensor.channel = OutputChannel(spec);
      scene::SettingsReader read(spec.settings);
      sensor.config = ReadConfig(sensor.kind, read, kAlternatives);
      std::visit(
          [&](auto& c) {
            if constexpr (OwnRate<std::decay_t<decltype(c)>>::value) c.rate_hz = spec.rate_hz;
          },
          sensor.config);
      read.RejectUnknownKeys(spec.type + " sensor");
      // The config's own checks, named with the sensor, at the line of the
      // key the message begins with (else the table's).
      try {
        std::visit([](const auto& c) { c.ValidateOrThrow(); }, sensor.config);
      } catch (const std::invalid_argument& error) {
        const std::string what = error.what();
        throw scene::LevelError(spec.settings.Where(what.substr(0, what.find(' '))) + what);
      }
      sensors.push_back(std::move(sensor));
    }
  }
  return sensors;
}

Sensor::Sensor(const MountedSensor& mounted)
    : mounted_(&mounted), sensor_(MakeClass(mounted.config, kAlternatives)) {
  std::visit(
      [this](const auto& s) { output_.emplace<typename std::decay_t<decltype(s)>::Output>(); },
      sensor_);
}

const SensorOutput& Sensor::Run(const SensorContext& at) {
  std::visit(
      [&](auto& sensor) {
        using Output = typename std::decay_t<decltype(sensor)>::Output;
        sensor.Run(at, &std::get<Output>(output_));
      },
      sensor_);
  return output_;
}

double Sensor::history_s() const {
  return std::visit([](const auto& s) { return HistoryOf<std::decay_t<decltype(s)>>::Of(s); },
                    sensor_);
}

}  // namespace sandbox::sensors
