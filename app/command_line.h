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

// A bad argument value; what() is shown to the user after "sandbox COMMAND: ".
struct CommandError : std::runtime_error {
  using std::runtime_error::runtime_error;
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

// "1,2.5,-3" as numbers; throws CommandError "OPTION: 'x' is not a finite number".
std::vector<double> ParseNumbers(const std::string& text, const std::string& option);

// Creates `path` and its parents unless they exist; throws CommandError
// "cannot create the output folder 'path'".
void CreateOutputFolder(const std::string& path);

// "X,Y,Z" or "X,Y,Z,ROLL,PITCH,YAW" (metres, degrees) as a pose; throws CommandError.
Eigen::Isometry3d ParsePose(const std::string& text, const std::string& option);

}  // namespace sandbox::app
