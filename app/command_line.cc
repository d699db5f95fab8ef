#include "app/command_line.h"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "scene/frames.h"

namespace sandbox::app {

std::string ParsedArgs::Value(const std::string& option, const std::string& fallback) const {
  const auto it = values.find(option);
  return it == values.end() ? fallback : it->second;
}

std::optional<ParsedArgs> ParseArgs(const std::vector<std::string>& args,
                                    const std::string& command,
                                    const std::set<std::string>& value_options,
                                    const std::set<std::string>& flags, const char* usage,
                                    std::ostream& err) {
  ParsedArgs parsed;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (arg == "--help" || arg == "-h") {
      parsed.help = true;
    } else if (value_options.count(arg) > 0 && i + 1 < args.size()) {
      parsed.values[arg] = args[++i];
    } else if (flags.count(arg) > 0) {
      parsed.flags.insert(arg);
    } else if (!arg.empty() && arg[0] == '-') {
      err << "sandbox " << command << ": unknown or incomplete option '" << arg << "'\n" << usage;
      return std::nullopt;
    } else if (!parsed.level) {
      parsed.level = arg;
    } else {
      err << "sandbox " << command << ": more than one level given ('" << *parsed.level << "', '"
          << arg << "')\n";
      return std::nullopt;
    }
  }
  return parsed;
}

std::vector<double> ParseNumbers(const std::string& text, const std::string& option) {
  std::vector<double> values;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    char* end = nullptr;
    const double value = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != '\0' || !std::isfinite(value)) {
      throw UsageError(option + ": '" + item + "' is not a finite number");
    }
    values.push_back(value);
  }
  return values;
}

double ParseNumber(const std::string& text, const std::string& option) {
  const std::vector<double> values = ParseNumbers(text, option);
  if (values.size() != 1) throw UsageError(option + " takes one number, got '" + text + "'");
  return values[0];
}

long long ParseWhole(const std::string& text, const std::string& option, long long min,
                     long long max) {
  const double value = ParseNumber(text, option);
  if (!(value >= double(min) && value <= double(max)) || value != std::floor(value)) {
    throw UsageError(option + " must be a whole number from " + std::to_string(min) + " to " +
                     std::to_string(max) + ", got '" + text + "'");
  }
  return static_cast<long long>(value);
}

Eigen::Isometry3d ParsePose(const std::string& text, const std::string& option) {
  const std::vector<double> v = ParseNumbers(text, option);
  if (v.size() != 3 && v.size() != 6) {
    throw UsageError(option + " takes X,Y,Z or X,Y,Z,ROLL,PITCH,YAW, got " +
                     std::to_string(v.size()) + " numbers");
  }
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
  if (v.size() == 6) {
    X.linear() = scene::RotationFromRollPitchYaw(v[3] * scene::kDegToRad, v[4] * scene::kDegToRad,
                                                 v[5] * scene::kDegToRad);
  }
  return X;
}

void CreateOutputFolder(const std::string& path) {
  std::error_code error;
  std::filesystem::create_directories(path, error);
  if (error || !std::filesystem::is_directory(path)) {
    throw CommandError("cannot create the output folder '" + path + "'");
  }
}

}  // namespace sandbox::app
