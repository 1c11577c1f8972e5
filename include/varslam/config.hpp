#pragma once
// The settings of a varslam session (C++17). Every key is declared once, with its default, valid range and meaning:
// docs/settings.md, or Config::describe(). A value is checked when it is set: an unknown key, a value of the wrong
// type, NaN or out of range is a ConfigError naming the key (and the file and line when it came from a file).
#include <memory>
#include <string>
#include <varslam/error.hpp>
#include <vector>

namespace varslam {

namespace detail {
struct ConfigAccess;
}

class Config {
 public:
  /// The defaults: a TUM fr1-like Kinect camera (640x480, fx 517.3), depth factor 5000, the paper's kernels.
  Config();
  /// A settings file: our own keys, or an ORB-SLAM3 settings file as it is.
  static Config from_file(const std::string& path);
  /// The same from YAML text; `name` stands for the file in messages.
  static Config from_yaml(const std::string& yaml, const std::string& name = "<yaml>");
  ~Config();
  Config(const Config&);
  Config& operator=(const Config&);
  Config(Config&&) noexcept;
  Config& operator=(Config&&) noexcept;

  /// Sets a key ("camera.fx", "tracking.kernel", ...) to a value written as in YAML ("600", "huber", "true").
  Config& set(const std::string& key, const std::string& value);
  Config& set(const std::string& key, double value);
  /// The key's value as text: the one set, else the one from the file, else the default.
  std::string get(const std::string& key) const;
  /// True when the key was set or given by the file (not only defaulted).
  bool given(const std::string& key) const;
  /// The file the settings came from; empty for defaults and YAML text.
  std::string source() const;
  /// Every declared key, and the reference text `varslam settings` prints.
  static std::vector<std::string> keys();
  static std::string describe();

 private:
  friend struct detail::ConfigAccess;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace varslam
