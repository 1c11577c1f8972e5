#include "io/settings.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <string_view>
#include <vector>

#include "core/error.hpp"

namespace varslam {
namespace {

// A value found in the document, with the key spelled as the user wrote it (for messages).
struct Found {
  YAML::Node node;
  std::string key;
};

std::vector<std::string> split_dots(std::string_view dotted) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  while (true) {
    const auto dot = dotted.find('.', start);
    parts.emplace_back(dotted.substr(start, dot - start));
    if (dot == std::string_view::npos) break;
    start = dot + 1;
  }
  return parts;
}

// Walks nested maps without assigning YAML::Node handles (assignment would overwrite the referenced node).
std::optional<YAML::Node> walk(const YAML::Node& node, const std::vector<std::string>& parts, std::size_t i) {
  if (i == parts.size()) return node;
  if (!node.IsMap()) return std::nullopt;
  const YAML::Node child = node[parts[i]];
  if (!child.IsDefined()) return std::nullopt;
  return walk(child, parts, i + 1);
}

// Looks a key up as a nested path ("camera.fx" -> camera: {fx: }) and then as one flat key with dots in its
// name, which is how ORB-SLAM3 files spell theirs ("Camera1.fx"). A null value counts as absent.
std::optional<Found> find_key(const YAML::Node& root, const std::string& dotted) {
  if (!root.IsMap()) return std::nullopt;
  if (auto n = walk(root, split_dots(dotted), 0); n && !n->IsNull()) return Found{*n, dotted};
  const YAML::Node flat = root[dotted];
  if (flat.IsDefined() && !flat.IsNull()) return Found{flat, dotted};
  return std::nullopt;
}

std::optional<Found> find_any(const YAML::Node& root, std::initializer_list<const char*> keys) {
  for (const char* k : keys)
    if (auto f = find_key(root, k)) return f;
  return std::nullopt;
}

std::string where(const std::filesystem::path& file, const Found& f) {
  const auto mark = f.node.Mark();
  const std::string name = file.empty() ? std::string("<settings>") : file.string();
  if (mark.line >= 0) return fmt::format("{}:{}: key '{}'", name, mark.line + 1, f.key);
  return fmt::format("{}: key '{}'", name, f.key);
}

std::string show(const YAML::Node& n) {
  if (n.IsScalar()) return "'" + n.Scalar() + "'";
  if (n.IsMap()) return "a map";
  if (n.IsSequence()) return "a list";
  return "nothing";
}

template <typename T>
const char* type_name();
template <>
const char* type_name<int>() { return "an integer"; }
template <>
const char* type_name<double>() { return "a number"; }
template <>
const char* type_name<bool>() { return "true or false"; }
template <>
const char* type_name<std::string>() { return "a string"; }

template <typename T>
std::optional<T> try_convert(const YAML::Node& n) {
  if (!n.IsScalar()) return std::nullopt;
  T v{};
  if (YAML::convert<T>::decode(n, v)) return v;
  return std::nullopt;
}

template <>
std::optional<int> try_convert<int>(const YAML::Node& n) {
  if (!n.IsScalar()) return std::nullopt;
  int v = 0;
  if (YAML::convert<int>::decode(n, v)) return v;
  // OpenCV writers sometimes spell integers as "640." or "30.0": accept integral doubles.
  double d = 0;
  if (YAML::convert<double>::decode(n, d) && std::isfinite(d) && d == std::floor(d) && std::abs(d) < 2e9)
    return static_cast<int>(d);
  return std::nullopt;
}

template <>
std::optional<bool> try_convert<bool>(const YAML::Node& n) {
  if (!n.IsScalar()) return std::nullopt;
  bool v = false;
  if (YAML::convert<bool>::decode(n, v)) return v;
  // ORB-SLAM files write flags as 0/1.
  if (n.Scalar() == "0") return false;
  if (n.Scalar() == "1") return true;
  return std::nullopt;
}

template <typename T>
T convert_or_throw(const std::filesystem::path& file, const Found& f) {
  if (auto v = try_convert<T>(f.node)) return *v;
  throw ConfigError(fmt::format("{}: expected {}, got {}", where(file, f), type_name<T>(), show(f.node)));
}

// Reads one field, trying each accepted spelling of its key in order.
class FieldReader {
 public:
  FieldReader(const YAML::Node& root, const std::filesystem::path& file) : root_(root), file_(file) {}

  template <typename T>
  bool read(T& out, std::initializer_list<const char*> keys) {
    auto f = find_any(root_, keys);
    if (!f) return false;
    out = convert_or_throw<T>(file_, *f);
    used_[&out] = f->key;
    return true;
  }
  template <typename T>
  void require(T& out, std::initializer_list<const char*> keys) {
    if (read(out, keys)) return;
    throw ConfigError(fmt::format("{}: missing required key '{}'", name(), *keys.begin()));
  }
  // Name of the key a field was read from (falls back to our own spelling for defaults).
  std::string key_of(const void* field, const char* fallback) const {
    auto it = used_.find(field);
    return it == used_.end() ? fallback : it->second;
  }
  void check(bool ok, const void* field, const char* fallback, const std::string& what) const {
    if (ok) return;
    const std::string key = key_of(field, fallback);
    const auto f = find_key(root_, key);
    const std::string loc = f ? where(file_, *f) : fmt::format("{}: key '{}'", name(), key);
    throw ConfigError(fmt::format("{}: {}", loc, what));
  }
  std::string name() const { return file_.empty() ? std::string("<settings>") : file_.string(); }

 private:
  const YAML::Node& root_;
  const std::filesystem::path& file_;
  std::map<const void*, std::string> used_;
};

// OpenCV's "%YAML:1.0" header is not valid YAML; comment it out (not remove it) so line numbers stay true.
std::string read_yaml_text(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw ConfigError(fmt::format("{}: cannot open settings file", file.string()));
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  if (text.rfind("%YAML:", 0) == 0 || text.rfind("%YAML 1.0", 0) == 0) text.insert(0, "# ");
  return text;
}

void validate(const Settings& s, const FieldReader& r) {
  const auto& c = s.camera;
  const auto finite = [](double v) { return std::isfinite(v); };
  r.check(finite(c.fx) && c.fx > 0, &c.fx, "camera.fx", fmt::format("fx must be > 0, got {}", c.fx));
  r.check(finite(c.fy) && c.fy > 0, &c.fy, "camera.fy", fmt::format("fy must be > 0, got {}", c.fy));
  r.check(finite(c.cx), &c.cx, "camera.cx", "cx must be finite");
  r.check(finite(c.cy), &c.cy, "camera.cy", "cy must be finite");
  for (const double* k : {&c.k1, &c.k2, &c.p1, &c.p2, &c.k3})
    r.check(finite(*k), k, "camera.distortion", "distortion coefficients must be finite");
  r.check(c.width > 0, &c.width, "camera.width", fmt::format("width must be > 0, got {}", c.width));
  r.check(c.height > 0, &c.height, "camera.height", fmt::format("height must be > 0, got {}", c.height));
  r.check(finite(c.bf) && c.bf > 0, &c.bf, "camera.baseline",
          fmt::format("baseline must be > 0 (bf = fx * baseline = {})", c.bf));
  r.check(finite(s.fps) && s.fps > 0, &s.fps, "camera.fps", fmt::format("fps must be > 0, got {}", s.fps));
  r.check(finite(s.depth_factor) && s.depth_factor > 0, &s.depth_factor, "depth.factor",
          fmt::format("depth factor must be > 0, got {}", s.depth_factor));
  r.check(finite(s.th_depth) && s.th_depth > 0, &s.th_depth, "depth.th_depth",
          fmt::format("th_depth must be > 0, got {}", s.th_depth));
  const auto& o = s.orb;
  r.check(o.n_features > 0, &o.n_features, "orb.n_features",
          fmt::format("n_features must be > 0, got {}", o.n_features));
  r.check(finite(o.scale_factor) && o.scale_factor > 1, &o.scale_factor, "orb.scale_factor",
          fmt::format("scale_factor must be > 1, got {}", o.scale_factor));
  r.check(o.n_levels >= 1, &o.n_levels, "orb.n_levels", fmt::format("n_levels must be >= 1, got {}", o.n_levels));
  r.check(o.ini_th_fast > 0, &o.ini_th_fast, "orb.ini_th_fast",
          fmt::format("ini_th_fast must be > 0, got {}", o.ini_th_fast));
  r.check(o.min_th_fast > 0 && o.min_th_fast <= o.ini_th_fast, &o.min_th_fast, "orb.min_th_fast",
          fmt::format("min_th_fast must be in [1, ini_th_fast={}], got {}", o.ini_th_fast, o.min_th_fast));
}

// Shortest text that reads back as the same double.
std::string num(double v) { return fmt::format("{}", v); }

}  // namespace

Settings default_settings() {
  // TUM fr1-like Kinect (freiburg1 intrinsics) without its distortion: our synthetic sequences are rendered
  // with an ideal pinhole. bf 40 = fx * ~7.7 cm, ORB-SLAM's usual Kinect value.
  Settings s;
  s.camera.fx = 517.3;
  s.camera.fy = 516.5;
  s.camera.cx = 318.6;
  s.camera.cy = 255.3;
  s.camera.k1 = s.camera.k2 = s.camera.p1 = s.camera.p2 = s.camera.k3 = 0.0;
  s.camera.width = 640;
  s.camera.height = 480;
  s.camera.bf = 40.0;
  s.fps = 30.0;
  s.depth_factor = 5000.0;
  s.th_depth = 40.0;
  s.orb = OrbSettings{};
  return s;
}

Settings load_settings(const std::filesystem::path& file) {
  YAML::Node root;
  try {
    root = YAML::Load(read_yaml_text(file));
  } catch (const YAML::Exception& e) {
    throw ConfigError(fmt::format("{}:{}: not valid YAML: {}", file.string(), e.mark.line + 1, e.msg));
  }
  return settings_from_yaml(root, file);
}

Settings settings_from_yaml(const YAML::Node& root, const std::filesystem::path& file) {
  Settings s = default_settings();
  s.source = file;
  s.root = root;
  if (!s.root.IsMap())
    throw ConfigError(fmt::format("{}: expected a YAML map of settings at the top level", file.string()));

  FieldReader r(s.root, file);
  auto& c = s.camera;
  // Our layout first (camera.*), then ORB-SLAM3 v1.0 (Camera1.*), then the older ORB-SLAM layout (Camera.*).
  r.require(c.fx, {"camera.fx", "Camera1.fx", "Camera.fx"});
  r.require(c.fy, {"camera.fy", "Camera1.fy", "Camera.fy"});
  r.require(c.cx, {"camera.cx", "Camera1.cx", "Camera.cx"});
  r.require(c.cy, {"camera.cy", "Camera1.cy", "Camera.cy"});
  r.read(c.k1, {"camera.k1", "Camera1.k1", "Camera.k1"});
  r.read(c.k2, {"camera.k2", "Camera1.k2", "Camera.k2"});
  r.read(c.p1, {"camera.p1", "Camera1.p1", "Camera.p1"});
  r.read(c.p2, {"camera.p2", "Camera1.p2", "Camera.p2"});
  r.read(c.k3, {"camera.k3", "Camera1.k3", "Camera.k3"});
  // ORB-SLAM2-era files have no image size; the dataset reader checks every image against these anyway.
  if (!r.read(c.width, {"camera.width", "Camera.width"}))
    spdlog::warn("{}: no camera width given, assuming {}", file.string(), c.width);
  if (!r.read(c.height, {"camera.height", "Camera.height"}))
    spdlog::warn("{}: no camera height given, assuming {}", file.string(), c.height);
  r.read(s.fps, {"camera.fps", "Camera.fps"});

  double baseline = 0.0;
  if (r.read(baseline, {"camera.baseline", "Stereo.b"})) {
    c.bf = c.fx * baseline;
    r.check(std::isfinite(baseline) && baseline > 0, &baseline, "camera.baseline",
            fmt::format("baseline must be > 0 m, got {}", baseline));
  } else {
    r.read(c.bf, {"camera.bf", "Camera.bf"});
  }

  if (!r.read(s.depth_factor, {"depth.factor", "RGBD.DepthMapFactor", "DepthMapFactor"}))
    spdlog::info("{}: no depth factor given, using {}", file.string(), s.depth_factor);
  r.read(s.th_depth, {"depth.th_depth", "Stereo.ThDepth", "ThDepth"});

  auto& o = s.orb;
  r.read(o.n_features, {"orb.n_features", "ORBextractor.nFeatures"});
  r.read(o.scale_factor, {"orb.scale_factor", "ORBextractor.scaleFactor"});
  r.read(o.n_levels, {"orb.n_levels", "ORBextractor.nLevels"});
  r.read(o.ini_th_fast, {"orb.ini_th_fast", "ORBextractor.iniThFAST"});
  r.read(o.min_th_fast, {"orb.min_th_fast", "ORBextractor.minThFAST"});

  validate(s, r);
  return s;
}

std::string settings_yaml(const Settings& s) {
  const auto& c = s.camera;
  std::string text = "# varslam settings (camera baseline in metres: bf = fx * baseline)\n";
  text += fmt::format(
      "camera:\n  fx: {}\n  fy: {}\n  cx: {}\n  cy: {}\n  k1: {}\n  k2: {}\n  p1: {}\n  p2: {}\n  k3: {}\n"
      "  width: {}\n  height: {}\n  fps: {}\n  baseline: {}\n",
      num(c.fx), num(c.fy), num(c.cx), num(c.cy), num(c.k1), num(c.k2), num(c.p1), num(c.p2), num(c.k3), c.width,
      c.height, num(s.fps), num(c.bf / c.fx));
  text += fmt::format("depth:\n  factor: {}\n  th_depth: {}\n", num(s.depth_factor), num(s.th_depth));
  text += fmt::format(
      "orb:\n  n_features: {}\n  scale_factor: {}\n  n_levels: {}\n  ini_th_fast: {}\n  min_th_fast: {}\n",
      s.orb.n_features, num(s.orb.scale_factor), s.orb.n_levels, s.orb.ini_th_fast, s.orb.min_th_fast);

  // Keep the stage sections; drop the ones written above and ORB-SLAM's flat dotted keys (now in ours).
  if (s.root.IsMap()) {
    YAML::Emitter e;
    e << YAML::BeginMap;
    bool any = false;
    for (const auto& kv : s.root) {
      const std::string key = kv.first.as<std::string>();
      if (key == "camera" || key == "depth" || key == "orb" || key.find('.') != std::string::npos) continue;
      e << YAML::Key << key << YAML::Value << kv.second;
      any = true;
    }
    e << YAML::EndMap;
    if (any) text += std::string(e.c_str()) + "\n";
  }
  return text;
}

void save_settings(const Settings& s, const std::filesystem::path& file) {
  const std::string text = settings_yaml(s);
  std::ofstream out(file);
  if (!out) throw ConfigError(fmt::format("{}: cannot write settings file", file.string()));
  out << text;
  if (!out) throw ConfigError(fmt::format("{}: error while writing settings file", file.string()));
}

template <typename T>
T setting_or(const Settings& s, const std::string& dotted_key, const T& fallback) {
  const auto f = find_key(s.root, dotted_key);
  if (!f) return fallback;
  return convert_or_throw<T>(s.source, *f);
}

template int setting_or<int>(const Settings&, const std::string&, const int&);
template double setting_or<double>(const Settings&, const std::string&, const double&);
template bool setting_or<bool>(const Settings&, const std::string&, const bool&);
template std::string setting_or<std::string>(const Settings&, const std::string&, const std::string&);

}  // namespace varslam
