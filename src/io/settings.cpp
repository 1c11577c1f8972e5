#include "io/settings.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <yaml-cpp/eventhandler.h>

#include <array>
#include <cerrno>
#include <cmath>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <string_view>
#include <system_error>
#include <vector>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "io/settings_registry.hpp"

namespace varslam {
namespace {

// Settings files are a few kilobytes; a file far larger is not one (a video or a map given by mistake), and is
// refused before it is read into memory.
constexpr std::size_t kMaxSettingsBytes = 1 << 20;
// Nodes a document may hold, counted through its aliases. yaml-cpp keeps an aliased node shared, so parsing stays
// cheap, but every later walk visits it once per alias: a few hundred bytes of aliases of aliases ("billion
// laughs") are billions of visits, and an alias inside its own anchor is a cycle no walk leaves. Real settings
// files hold under a hundred values; the budget is a hundred times that, and walking it takes milliseconds.
constexpr std::size_t kMaxSettingsNodes = 10000;

std::string errno_text(int e) { return std::error_code(e, std::generic_category()).message(); }

// What stands in the way of reading `file`, said before trying: a folder opens as a stream that reads nothing,
// and a link to nowhere would otherwise be "cannot open".
void check_settings_file(const std::filesystem::path& file) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status link = fs::symlink_status(file, ec);
  if (!fs::exists(link)) throw ConfigError(fmt::format("{}: settings file not found", file.string()));
  const fs::file_status target = fs::status(file, ec);
  if (fs::is_symlink(link) && !fs::exists(target))
    throw ConfigError(fmt::format("{}: the settings file is a symbolic link to {}, which does not exist",
                                  file.string(), fs::read_symlink(file, ec).string()));
  if (fs::is_directory(target))
    throw ConfigError(fmt::format("{}: is a folder, not a settings file", file.string()));
}

// OpenCV's "%YAML:1.0" header is not valid YAML; comment it out (not remove it) so line numbers stay true.
std::string read_yaml_text(const std::filesystem::path& file) {
  check_settings_file(file);
  errno = 0;
  std::ifstream in(file, std::ios::binary);
  if (!in) throw ConfigError(fmt::format("{}: cannot open the settings file: {}", file.string(), errno_text(errno)));
  // In pieces up to the limit: a pipe has no size to check first, and a settings file is small.
  std::string text;
  std::array<char, 16384> piece;
  while (in.read(piece.data(), piece.size()) || in.gcount() > 0) {
    text.append(piece.data(), static_cast<std::size_t>(in.gcount()));
    if (text.size() > kMaxSettingsBytes)
      throw ConfigError(fmt::format("{}: larger than {} KiB; a settings file is a few kilobytes of YAML",
                                    file.string(), kMaxSettingsBytes / 1024));
  }
  if (in.bad())
    throw ConfigError(fmt::format("{}: cannot read the settings file: {}", file.string(), errno_text(errno)));
  if (text.rfind("%YAML:", 0) == 0 || text.rfind("%YAML 1.0", 0) == 0) text.insert(0, "# ");
  return text;
}

// Visits every node as a reader would (an alias as often as it is used) and stops at the budget, before any
// unbounded walk over the tree starts.
void check_node_budget(const YAML::Node& root, const std::string& name) {
  std::vector<YAML::Node> todo{root};
  std::size_t visited = 0;
  while (!todo.empty()) {
    const YAML::Node n = todo.back();
    todo.pop_back();
    if (++visited > kMaxSettingsNodes)
      throw ConfigError(fmt::format("{}: the YAML expands to more than {} values (aliases of aliases, or an alias "
                                    "inside its own anchor); a settings file holds a hundred or so",
                                    name, kMaxSettingsNodes));
    if (n.IsMap()) {
      for (const auto& kv : n) {
        todo.push_back(kv.first);
        todo.push_back(kv.second);
      }
    } else if (n.IsSequence()) {
      for (const auto& item : n) todo.push_back(item);
    }
  }
}

// What the registry's per-key ranges cannot say: relations between keys.
void check_relations(const Settings& s) {
  const std::string where = s.source.empty() ? std::string("<settings>") : s.source.string();
  // camera.bf defaults to a Kinect's 40 whatever camera.fx is; what it means is the baseline bf / fx.
  const double baseline = s.camera.bf / s.camera.fx;
  constexpr double kMaxBaseline = 10.0;  // camera.baseline's range
  if (!(baseline > 0 && baseline <= kMaxBaseline))
    throw ConfigError(fmt::format("{}: camera.bf {} with camera.fx {} is a baseline of {:g} m (at most {:g}); give "
                                  "camera.baseline in metres",
                                  where, s.camera.bf, s.camera.fx, baseline, kMaxBaseline));
  const auto& o = s.orb;
  if (o.min_th_fast > o.ini_th_fast)
    throw ConfigError(fmt::format("{}: orb.min_th_fast ({}) must not exceed orb.ini_th_fast ({})",
                                  s.source.empty() ? std::string("<settings>") : s.source.string(), o.min_th_fast,
                                  o.ini_th_fast));
}

// Shortest text that reads back as the same double.
std::string num(double v) { return fmt::format("{}", v); }

}  // namespace

Settings default_settings() {
  // TUM fr1-like Kinect (freiburg1 intrinsics) without its distortion: our synthetic sequences are rendered
  // with an ideal pinhole; the values are the registry's defaults.
  Settings s;
  s.camera.fx = setting_keys::real_default("camera.fx");
  s.camera.fy = setting_keys::real_default("camera.fy");
  s.camera.cx = setting_keys::real_default("camera.cx");
  s.camera.cy = setting_keys::real_default("camera.cy");
  s.camera.k1 = setting_keys::real_default("camera.k1");
  s.camera.k2 = setting_keys::real_default("camera.k2");
  s.camera.p1 = setting_keys::real_default("camera.p1");
  s.camera.p2 = setting_keys::real_default("camera.p2");
  s.camera.k3 = setting_keys::real_default("camera.k3");
  s.camera.width = setting_keys::int_default("camera.width");
  s.camera.height = setting_keys::int_default("camera.height");
  s.camera.bf = setting_keys::real_default("camera.bf");
  return s;
}

namespace {

/// Settings keys are names. YAML also allows a map or a list as a key; that has no meaning here, and written back
/// such a key does not read again.
void check_keys_are_names(const YAML::Node& node, const std::string& name) {
  if (node.IsMap()) {
    for (const auto& kv : node) {
      if (!kv.first.IsScalar())
        throw ConfigError(fmt::format("{}:{}: a key must be a name, not a {}", name, kv.first.Mark().line + 1,
                                      kv.first.IsMap() ? "map" : "list"));
      check_keys_are_names(kv.second, name);
    }
  } else if (node.IsSequence()) {
    for (const auto& item : node) check_keys_are_names(item, name);
  }
}

// Whether a YAML document holds anything but an empty value, and the line where that starts.
class DocumentContent final : public YAML::EventHandler {
 public:
  std::optional<int> line;  // 0-based; empty while nothing was seen
  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark& m, YAML::anchor_t) override { seen(m); }
  void OnScalar(const YAML::Mark& m, const std::string&, YAML::anchor_t, const std::string&) override { seen(m); }
  void OnSequenceStart(const YAML::Mark& m, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {
    seen(m);
  }
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark& m, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {
    seen(m);
  }
  void OnMapEnd() override {}

 private:
  void seen(const YAML::Mark& m) {
    if (!line) line = m.line;
  }
};

// Only the first document is read: what a later one says would be ignored without a word. The documents are
// walked by count, not with YAML::LoadAll: yaml-cpp 0.7 reports empty documents forever on some malformed input
// (found by fuzzing), and LoadAll then never returns.
void check_one_document(const std::string& text, const std::string& name) {
  constexpr int kMaxDocuments = 1000;
  std::istringstream in(text);
  YAML::Parser parser(in);
  for (int i = 0; i < kMaxDocuments; ++i) {
    DocumentContent doc;
    if (!parser.HandleNextDocument(doc)) return;
    if (i > 0 && doc.line)  // an empty one (a trailing '---') adds nothing
      throw ConfigError(fmt::format("{}:{}: a second YAML document (after a '---' line); a settings file is one "
                                    "document: remove the '---' or move its keys into the first",
                                    name, *doc.line + 1));
  }
  throw ConfigError(fmt::format("{}: more than {} YAML documents; a settings file is one", name, kMaxDocuments));
}

}  // namespace

YAML::Node parse_settings_yaml(const std::string& text, const std::string& name) {
  if (text.size() > kMaxSettingsBytes)
    throw ConfigError(fmt::format("{}: larger than {} KiB; settings are a few kilobytes of YAML", name,
                                  kMaxSettingsBytes / 1024));
  try {
    YAML::Node root = YAML::Load(text);
    check_one_document(text, name);
    return root;
  } catch (const YAML::Exception& e) {
    throw ConfigError(fmt::format("{}:{}: not valid YAML: {}", name, e.mark.line + 1, e.msg));
  }
}

Settings load_settings(const std::filesystem::path& file) {
  return settings_from_yaml(parse_settings_yaml(read_yaml_text(file), file.string()), file);
}

Settings settings_from_yaml(const YAML::Node& root, const std::filesystem::path& file,
                            const std::map<std::string, std::string>& overrides) {
  Settings s = default_settings();
  s.source = file;
  s.root = root;
  s.overrides = overrides;
  check_node_budget(s.root, file.empty() ? std::string("<settings>") : file.string());
  if (!s.root.IsMap())
    throw ConfigError(fmt::format("{}: expected a YAML map of settings at the top level", file.string()));
  check_keys_are_names(s.root, file.empty() ? std::string("<settings>") : file.string());
  check_settings_document(s.root, file, overrides);

  const std::string name = file.empty() ? std::string("<settings>") : file.string();
  auto& c = s.camera;
  for (const char* key : {"camera.fx", "camera.fy", "camera.cx", "camera.cy"})
    if (!setting_given(s, key)) throw ConfigError(fmt::format("{}: missing required key '{}'", name, key));
  c.fx = setting<double>(s, "camera.fx");
  c.fy = setting<double>(s, "camera.fy");
  c.cx = setting<double>(s, "camera.cx");
  c.cy = setting<double>(s, "camera.cy");
  c.k1 = setting<double>(s, "camera.k1");
  c.k2 = setting<double>(s, "camera.k2");
  c.p1 = setting<double>(s, "camera.p1");
  c.p2 = setting<double>(s, "camera.p2");
  c.k3 = setting<double>(s, "camera.k3");
  // ORB-SLAM2-era files have no image size; the dataset reader checks every image against these anyway.
  if (!setting_given(s, "camera.width")) spdlog::warn("{}: no camera width given, assuming {}", name, c.width);
  if (!setting_given(s, "camera.height")) spdlog::warn("{}: no camera height given, assuming {}", name, c.height);
  c.width = setting<int>(s, "camera.width");
  c.height = setting<int>(s, "camera.height");
  s.fps = setting<double>(s, "camera.fps");
  if (const auto baseline = setting_if_given(s, "camera.baseline"))
    c.bf = c.fx * *baseline;
  else
    c.bf = setting<double>(s, "camera.bf");

  if (!setting_given(s, "depth.factor")) spdlog::info("{}: no depth factor given, using {}", name, s.depth_factor);
  s.depth_factor = setting<double>(s, "depth.factor");
  s.th_depth = setting<double>(s, "depth.th_depth");

  auto& o = s.orb;
  o.n_features = setting<int>(s, "orb.n_features");
  o.scale_factor = setting<double>(s, "orb.scale_factor");
  o.n_levels = setting<int>(s, "orb.n_levels");
  o.ini_th_fast = setting<int>(s, "orb.ini_th_fast");
  o.min_th_fast = setting<int>(s, "orb.min_th_fast");
  o.threads = setting<int>(s, "orb.threads");
  check_relations(s);
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
      "orb:\n  n_features: {}\n  scale_factor: {}\n  n_levels: {}\n  ini_th_fast: {}\n  min_th_fast: {}\n  threads: {}\n",
      s.orb.n_features, num(s.orb.scale_factor), s.orb.n_levels, s.orb.ini_th_fast, s.orb.min_th_fast,
      s.orb.threads);

  // Keep the stage sections; drop the ones written above, ORB-SLAM's flat dotted keys and its undotted spellings of
  // ours (DepthMapFactor, ThDepth): written above in our spelling, they would be a second spelling of the key.
  if (s.root.IsMap()) {
    YAML::Emitter e;
    e << YAML::BeginMap;
    bool any = false;
    for (const auto& kv : s.root) {
      const std::string key = kv.first.as<std::string>();
      if (key == "camera" || key == "depth" || key == "orb" || key.find('.') != std::string::npos ||
          spec_for_spelling(key))
        continue;
      e << YAML::Key << key << YAML::Value << kv.second;
      any = true;
    }
    e << YAML::EndMap;
    if (any) text += std::string(e.c_str()) + "\n";
  }
  return text;
}

void save_settings(const Settings& s, const std::filesystem::path& file) {
  write_file_atomically(file, settings_yaml(s), "settings file");
}

}  // namespace varslam
