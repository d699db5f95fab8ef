#pragma once
// Settings of a manifest table that another module interprets (a sensor's,
// a robot's bridge): kept as given, with where each stands, and read with one
// clear LevelError per mistake.

#include <filesystem>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "scene/placement.h"

namespace sandbox::scene {

using SettingValue =
    std::variant<double, bool, std::string, std::vector<double>, std::vector<std::string>>;

struct SettingsTable {
  std::map<std::string, SettingValue> values;
  std::map<std::string, int> lines;  // the line of each key
  std::filesystem::path file;        // the manifest
  int line{0};                       // the table's line
  std::string context;               // "sensor 'scanner'", "robot 'ELAHA' bridge"

  // "level.toml:12: sensor 'scanner': ", at the key's line when it is known.
  std::string Where(const std::string& key = "") const;
};

// "a, b or c": the values a setting may take, for messages.
std::string ChoiceList(const std::vector<std::string_view>& choices);

// Typed access; remembers which keys were read so that the rest can be
// rejected as unknown. The manifest's own TableReader (manifest.cc) uses the
// same verbs: Text, Flag, Number, Whole, Numbers.
class SettingsReader {
 public:
  explicit SettingsReader(const SettingsTable& table) : table_(table) {}

  [[noreturn]] void Fail(const std::string& key, const std::string& what) const;
  double Number(const std::string& key, double fallback);
  int Whole(const std::string& key, int fallback);
  bool Flag(const std::string& key, bool fallback);
  std::string Text(const std::string& key, const std::string& fallback);
  std::vector<double> Numbers(const std::string& key);
  std::vector<std::string> Texts(const std::string& key);
  // Whether the table sets `key` (asked for, as by the verbs above).
  bool Has(const std::string& key);
  // A key that is no more: throws naming it and `instead` when the table sets it.
  void Removed(const std::string& key, const std::string& instead) const;
  // Throws for every key not read, naming `kind` ("face sensor").
  void RejectUnknownKeys(const std::string& kind) const;

 private:
  const SettingValue* Find(const std::string& key);
  const SettingsTable& table_;
  std::set<std::string> read_;
};

// The keys each kind of manifest table accepts, as its readers ask for them:
// every reader reports, when it checks for keys it did not ask for, the
// table's kind ("[[actor]]", "face sensor") and the keys it asked for. For
// the docs-against-code test (docs/reference/manifest.md); nothing is kept
// unless a listener is set. Set it before loading, on one thread.
using KeyListener =
    std::function<void(const std::string& table, const std::set<std::string>& keys)>;
void SetKeyListener(KeyListener listener);
void ReportKeys(const std::string& table, const std::set<std::string>& keys);

}  // namespace sandbox::scene
