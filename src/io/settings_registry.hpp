#pragma once
// Reads and checks settings against the declared registry (core/setting_keys.hpp): typed reads with the
// registry's defaults, the whole-document check (unknown sections and keys with the nearest valid one, duplicate
// keys, wrong types, NaN, values out of range), command-line overrides, and the settings reference.
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/setting_keys.hpp"
#include "io/settings.hpp"

namespace varslam {

/// The declared key `name`; throws std::logic_error for an undeclared one (a programming error, not user input).
const setting_keys::KeySpec& key_spec(std::string_view name);

/// The declared key a document spelling stands for: our own name or an ORB-SLAM alias ("Camera1.fx",
/// "DepthMapFactor"); nullptr when it is neither.
const setting_keys::KeySpec* spec_for_spelling(std::string_view spelled);

/// The value of a declared key: from the document (or an override) when given, else the registry's default.
/// T: int, double, bool, std::string (Choice / Text / Path), std::vector<std::string>, std::map<string, string>.
/// A wrong type or a value outside the key's range is a ConfigError naming the source (file:line or --set).
template <typename T>
T setting(const Settings& s, std::string_view key);
/// True when the document (or an override) gives the key, in any accepted spelling.
bool setting_given(const Settings& s, std::string_view key);
/// The same for a key without a default: empty when the document does not give it.
std::optional<double> setting_if_given(const Settings& s, std::string_view key);

/// Checks every key of a settings document: sections and keys must be declared (or be an ORB-SLAM key varslam
/// ignores), appear once, and hold a value of their type within their range. `overrides` maps a dotted key to
/// the command-line text that set it, so errors name that instead of the file.
void check_settings_document(const YAML::Node& root, const std::filesystem::path& file,
                             const std::map<std::string, std::string>& overrides = {});

/// Applies "section.key=value" overrides (`--set`) to the settings: each key must be declared and its value valid,
/// else a ConfigError naming `--set 'section.key=value'`. Camera, depth and ORB fields are read again.
void apply_setting_overrides(Settings& settings, const std::vector<std::string>& overrides);

/// The declared key nearest to `name` by edit distance ("tracking.kernl" -> "tracking.kernel"); empty when none
/// is close. `section_only`: compare with section names.
std::string nearest_key(std::string_view name, bool section_only = false);

/// Every key with its type, default, range or choices and meaning: `varslam settings` and docs/settings.md.
std::string settings_reference_text();
std::string settings_reference_markdown();

/// "3", "[0, 1]", "(0, 1e+05]", "auto | off": how the reference shows a key's default and valid values.
std::string default_text(const setting_keys::KeySpec& k);
std::string range_text(const setting_keys::KeySpec& k);

}  // namespace varslam
