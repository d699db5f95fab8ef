#include "scene/settings.h"

#include <cmath>

namespace sandbox::scene {

std::string ChoiceList(const std::vector<std::string_view>& choices) {
  std::string list;
  for (std::size_t i = 0; i < choices.size(); ++i) {
    list += i == 0 ? "" : i + 1 == choices.size() ? " or " : ", ";
    list += choices[i];
  }
  return list;
}

std::string SettingsTable::Where(const std::string& key) const {
  const auto at = lines.find(key);
  const int where = at == lines.end() ? line : at->second;
  return file.string() + ":" + std::to_string(where) + ": " + context + ": ";
}

void SettingsReader::Fail(const std::string& key, const std::string& what) const {
  throw LevelError(table_.Where(key) + what);
}

const SettingValue* SettingsReader::Find(const std::string& key) {
  read_.insert(key);
  const auto it = table_.values.find(key);
  return it == table_.values.end() ? nullptr : &it->second;
}

bool SettingsReader::Has(const std::string& key) { return Find(key) != nullptr; }

void SettingsReader::Removed(const std::string& key, const std::string& instead) const {
  if (table_.values.count(key) > 0) Fail(key, "'" + key + "' is no longer a key: " + instead);
}

double SettingsReader::Number(const std::string& key, double fallback) {
  const SettingValue* value = Find(key);
  if (value == nullptr) return fallback;
  if (!std::holds_alternative<double>(*value)) Fail(key, "'" + key + "' must be a number");
  return std::get<double>(*value);
}

int SettingsReader::Whole(const std::string& key, int fallback) {
  const double value = Number(key, fallback);
  if (value != std::floor(value) || std::abs(value) > 1e9) {
    Fail(key, "'" + key + "' must be a whole number");
  }
  return static_cast<int>(value);
}

bool SettingsReader::Flag(const std::string& key, bool fallback) {
  const SettingValue* value = Find(key);
  if (value == nullptr) return fallback;
  if (!std::holds_alternative<bool>(*value)) Fail(key, "'" + key + "' must be true or false");
  return std::get<bool>(*value);
}

std::string SettingsReader::Text(const std::string& key, const std::string& fallback) {
  const SettingValue* value = Find(key);
  if (value == nullptr) return fallback;
  if (!std::holds_alternative<std::string>(*value)) Fail(key, "'" + key + "' must be a string");
  return std::get<std::string>(*value);
}

std::vector<double> SettingsReader::Numbers(const std::string& key) {
  const SettingValue* value = Find(key);
  if (value == nullptr) return {};
  if (!std::holds_alternative<std::vector<double>>(*value)) {
    Fail(key, "'" + key + "' must be an array of numbers");
  }
  return std::get<std::vector<double>>(*value);
}

std::vector<std::string> SettingsReader::Texts(const std::string& key) {
  const SettingValue* value = Find(key);
  if (value == nullptr) return {};
  if (!std::holds_alternative<std::vector<std::string>>(*value)) {
    Fail(key, "'" + key + "' must be an array of strings");
  }
  return std::get<std::vector<std::string>>(*value);
}

namespace {
KeyListener& Listener() {
  static KeyListener listener;
  return listener;
}
}  // namespace

void SetKeyListener(KeyListener listener) { Listener() = std::move(listener); }

void ReportKeys(const std::string& table, const std::set<std::string>& keys) {
  if (Listener()) Listener()(table, keys);
}

void SettingsReader::RejectUnknownKeys(const std::string& kind) const {
  ReportKeys(kind, read_);
  for (const auto& [key, value] : table_.values) {
    if (read_.count(key) == 0) {
      const bool vowel = !kind.empty() && std::string("aeiou").find(kind[0]) != std::string::npos;
      Fail(key, "unknown key '" + key + "' for " + (vowel ? "an " : "a ") + kind);
    }
  }
}

}  // namespace sandbox::scene
