#pragma once
// Command-line parsing shared by the subcommands.

#include <Eigen/Geometry>
#include <map>
#include <optional>
#include <ostream>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace sandbox::app {

// A command that cannot be done; what() is shown to the user after
// "sandbox COMMAND: " and the exit code is 1.
struct CommandError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A mistake on the command line (a bad value or combination of options):
// exit code 2, like an unknown option.
struct UsageError : CommandError {
  using CommandError::CommandError;
};

struct ParsedArgs {
  std::map<std::string, std::string> values;  // --option VALUE
  std::set<std::string> flags;                // --flag
  std::optional<std::string> level;           // the one positional argument
  bool help{false};

  std::string Value(const std::string& option, const std::string& fallback = "") const;
};

// Parses `args` of `command` ("sandbox COMMAND ..."). Returns nullopt after
// printing the mistake and the usage to `err` (the exit code is then 2).
std::optional<ParsedArgs> ParseArgs(const std::vector<std::string>& args,
                                    const std::string& command,
                                    const std::set<std::string>& value_options,
                                    const std::set<std::string>& flags, const char* usage,
                                    std::ostream& err);

// "1,2.5,-3" as numbers; throws UsageError "OPTION: 'x' is not a finite number".
std::vector<double> ParseNumbers(const std::string& text, const std::string& option);
// Exactly one finite number; throws UsageError naming the option.
double ParseNumber(const std::string& text, const std::string& option);
// A whole number in [min, max]; throws UsageError naming the option and the range.
long long ParseWhole(const std::string& text, const std::string& option, long long min,
                     long long max);

// Creates `path` and its parents unless they exist; throws CommandError
// "cannot create the output folder 'path'".
void CreateOutputFolder(const std::string& path);

// "X,Y,Z" or "X,Y,Z,ROLL,PITCH,YAW" (metres, degrees) as a pose; throws UsageError.
Eigen::Isometry3d ParsePose(const std::string& text, const std::string& option);

}  // namespace sandbox::app
