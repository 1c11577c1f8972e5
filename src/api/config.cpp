// varslam::Config: the public face of the settings (io/settings.hpp and the registry).
#include <fmt/format.h>

#include <varslam/config.hpp>

#include "api/config_access.hpp"
#include "io/settings_registry.hpp"

namespace varslam {

struct Config::Impl {
  Settings settings = default_settings();
};

Config::Config() : impl_(std::make_unique<Impl>()) {}
Config::~Config() = default;
Config::Config(const Config& other) : impl_(std::make_unique<Impl>()) {
  impl_->settings = detail::ConfigAccess::settings(other);
}
Config& Config::operator=(const Config& other) {
  if (this != &other) *this = Config(other);
  return *this;
}
Config::Config(Config&&) noexcept = default;
Config& Config::operator=(Config&&) noexcept = default;

Config Config::from_file(const std::string& path) {
  Config c;
  c.impl_->settings = load_settings(path);
  return c;
}

Config Config::from_yaml(const std::string& yaml, const std::string& name) {
  Config c;
  c.impl_->settings = settings_from_yaml(parse_settings_yaml(yaml, name), name);
  c.impl_->settings.source.clear();  // not a file: relative paths are relative to the working folder
  return c;
}

Config& Config::set(const std::string& key, const std::string& value) {
  apply_setting_overrides(impl_->settings, {key + "=" + value});
  return *this;
}

Config& Config::set(const std::string& key, double value) { return set(key, fmt::format("{}", value)); }

std::string Config::get(const std::string& key) const {
  using setting_keys::KeyType;
  const Settings& s = impl_->settings;
  const setting_keys::KeySpec* spec = nullptr;
  for (const auto& k : setting_keys::all())
    if (k.name == key) spec = &k;
  if (!spec) {
    const std::string near = nearest_key(key);
    throw ConfigError(
        fmt::format("unknown settings key '{}'{}", key, near.empty() ? "" : "; did you mean '" + near + "'?"));
  }
  switch (spec->type) {
    case KeyType::Int:
      return std::to_string(setting<int>(s, key));
    case KeyType::Real:
      if (!spec->has_default) {
        const auto v = setting_if_given(s, key);
        return v ? fmt::format("{}", *v) : std::string();
      }
      return fmt::format("{}", setting<double>(s, key));
    case KeyType::Bool:
      return setting<bool>(s, key) ? "true" : "false";
    case KeyType::Choice:
    case KeyType::Text:
    case KeyType::Path:
      return setting<std::string>(s, key);
    case KeyType::TextList:
      return fmt::format("{}", fmt::join(setting<std::vector<std::string>>(s, key), ","));
    case KeyType::TextMap: {
      std::vector<std::string> pairs;
      for (const auto& [from, to] : setting<std::map<std::string, std::string>>(s, key))
        pairs.push_back(from + ":" + to);
      return fmt::format("{}", fmt::join(pairs, ","));
    }
  }
  return {};
}

bool Config::given(const std::string& key) const { return setting_given(impl_->settings, key); }

std::string Config::source() const { return impl_->settings.source.string(); }

std::vector<std::string> Config::keys() {
  std::vector<std::string> out;
  for (const auto& k : setting_keys::all()) out.emplace_back(k.name);
  return out;
}

std::string Config::describe() { return settings_reference_text(); }

Settings detail::ConfigAccess::settings(const Config& c) {
  Settings s = c.impl_->settings;
  s.root.reset(YAML::Clone(c.impl_->settings.root));  // a YAML node copy shares its data: clone it
  return s;
}

Config detail::ConfigAccess::wrap(Settings s) {
  Config c;
  c.impl_->settings = std::move(s);
  return c;
}

}  // namespace varslam
