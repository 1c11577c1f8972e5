#include "io/settings_registry.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>
#include <sstream>
#include <stdexcept>

#include "core/error.hpp"

namespace varslam {
namespace {
using setting_keys::KeySpec;
using setting_keys::KeyType;

std::vector<std::string_view> split(std::string_view text, char sep) {
  std::vector<std::string_view> parts;
  if (text.empty()) return parts;
  std::size_t start = 0;
  while (true) {
    const auto at = text.find(sep, start);
    parts.push_back(text.substr(start, at - start));
    if (at == std::string_view::npos) break;
    start = at + 1;
  }
  return parts;
}

std::pair<std::string_view, std::string_view> section_and_key(std::string_view dotted) {
  const auto dot = dotted.find('.');
  return {dotted.substr(0, dot), dot == std::string_view::npos ? std::string_view{} : dotted.substr(dot + 1)};
}

// Where a value came from, for messages: the --set text that gave it, else file:line.
std::string where(const std::filesystem::path& file, const std::map<std::string, std::string>& overrides,
                  const YAML::Node& node, std::string_view key) {
  if (auto it = overrides.find(std::string(key)); it != overrides.end()) return it->second;
  const std::string name = file.empty() ? std::string("<settings>") : file.string();
  const auto mark = node.Mark();
  if (mark.line >= 0) return fmt::format("{}:{}: key '{}'", name, mark.line + 1, key);
  return fmt::format("{}: key '{}'", name, key);
}

std::string show(const YAML::Node& n) {
  if (n.IsScalar()) return "'" + n.Scalar() + "'";
  if (n.IsMap()) return "a map";
  if (n.IsSequence()) return "a list";
  return "nothing";
}

std::optional<double> as_number(const YAML::Node& n) {
  if (!n.IsScalar()) return std::nullopt;
  double v = 0;
  if (!YAML::convert<double>::decode(n, v)) return std::nullopt;
  return v;
}

std::optional<bool> as_bool(const YAML::Node& n) {
  if (!n.IsScalar()) return std::nullopt;
  bool v = false;
  if (YAML::convert<bool>::decode(n, v)) return v;
  if (n.Scalar() == "0") return false;  // ORB-SLAM files write flags as 0/1
  if (n.Scalar() == "1") return true;
  return std::nullopt;
}

bool in_range(const KeySpec& k, double v) {
  const bool lo_ok = k.lo_open ? v > k.lo : v >= k.lo;
  const bool hi_ok = k.hi_open ? v < k.hi : v <= k.hi;
  return lo_ok && hi_ok;
}

const char* type_text(KeyType t) {
  switch (t) {
    case KeyType::Int: return "an integer";
    case KeyType::Real: return "a number";
    case KeyType::Bool: return "true or false";
    case KeyType::Choice: return "one of the choices";
    case KeyType::Text: return "a string";
    case KeyType::Path: return "a path";
    case KeyType::TextList: return "a list of strings";
    case KeyType::TextMap: return "a map of strings";
  }
  return "?";
}

// Checks a given value against its declaration; `loc` names its source.
void check_value(const KeySpec& k, const YAML::Node& n, const std::string& loc) {
  const auto fail = [&](const std::string& what) { throw ConfigError(fmt::format("{}: {}", loc, what)); };
  switch (k.type) {
    case KeyType::Int:
    case KeyType::Real: {
      const auto v = as_number(n);
      if (!v) fail(fmt::format("expected {}, got {}", type_text(k.type), show(n)));
      if (!std::isfinite(*v)) fail(fmt::format("must be a finite number, got {}", show(n)));
      if (k.type == KeyType::Int && *v != std::floor(*v)) fail(fmt::format("expected an integer, got {}", show(n)));
      if (!in_range(k, *v)) fail(fmt::format("must be in {}, got {}", range_text(k), n.Scalar()));
      return;
    }
    case KeyType::Bool:
      if (!as_bool(n)) fail(fmt::format("expected true or false, got {}", show(n)));
      return;
    case KeyType::Choice: {
      if (!n.IsScalar()) fail(fmt::format("expected one of {}, got {}", range_text(k), show(n)));
      const auto options = split(k.choices, '|');
      if (std::find(options.begin(), options.end(), n.Scalar()) == options.end())
        fail(fmt::format("must be one of {}, got {}", range_text(k), show(n)));
      return;
    }
    case KeyType::Text:
    case KeyType::Path:
      if (!n.IsScalar()) fail(fmt::format("expected {}, got {}", type_text(k.type), show(n)));
      return;
    case KeyType::TextList:
      if (!n.IsSequence()) fail(fmt::format("expected a list of strings (e.g. [person]), got {}", show(n)));
      for (const auto& item : n)
        if (!item.IsScalar()) fail(fmt::format("expected a list of strings, one item is {}", show(item)));
      return;
    case KeyType::TextMap:
      if (!n.IsMap()) fail(fmt::format("expected a map of strings (e.g. {{body: person}}), got {}", show(n)));
      for (const auto& kv : n)
        if (!kv.second.IsScalar()) fail(fmt::format("expected a map of strings, '{}' maps to {}",
                                                    kv.first.Scalar(), show(kv.second)));
      return;
  }
}

// Walks nested maps without assigning YAML::Node handles (assignment would overwrite the referenced node).
std::optional<YAML::Node> walk(const YAML::Node& node, const std::vector<std::string_view>& parts, std::size_t i) {
  if (i == parts.size()) return node;
  if (!node.IsMap()) return std::nullopt;
  const YAML::Node child = node[std::string(parts[i])];
  if (!child.IsDefined()) return std::nullopt;
  return walk(child, parts, i + 1);
}

struct Found {
  YAML::Node node;
  std::string key;  // as spelled in the document
};

// A key as a nested path ("camera.fx" -> camera: {fx: }), then as one flat key with dots in its name (how
// ORB-SLAM3 files spell theirs: "Camera1.fx"). A null value counts as absent.
std::optional<Found> find_spelling(const YAML::Node& root, std::string_view dotted) {
  if (!root || !root.IsMap()) return std::nullopt;
  if (auto n = walk(root, split(dotted, '.'), 0); n && !n->IsNull()) return Found{*n, std::string(dotted)};
  const YAML::Node flat = root[std::string(dotted)];
  if (flat.IsDefined() && !flat.IsNull()) return Found{flat, std::string(dotted)};
  return std::nullopt;
}

// Every place the document gives `k` a value, in each of its spellings (ours nested or flat, ORB-SLAM's).
std::vector<Found> spellings_given(const YAML::Node& root, const KeySpec& k) {
  std::vector<Found> found;
  if (!root || !root.IsMap()) return found;
  const auto add = [&](std::string_view spelled) {
    if (auto n = walk(root, split(spelled, '.'), 0); n && !n->IsNull()) found.push_back({*n, std::string(spelled)});
    if (spelled.find('.') == std::string_view::npos) return;  // "ThDepth": the walk found the same node
    const YAML::Node flat = root[std::string(spelled)];
    if (flat.IsDefined() && !flat.IsNull()) found.push_back({flat, std::string(spelled)});
  };
  add(k.name);
  for (std::string_view alias : split(k.aliases, '|')) add(alias);
  return found;
}

std::optional<Found> find_value(const YAML::Node& root, const KeySpec& k) {
  if (auto f = find_spelling(root, k.name)) return f;
  for (std::string_view alias : split(k.aliases, '|'))
    if (auto f = find_spelling(root, alias)) return f;
  return std::nullopt;
}

bool is_ignored_foreign_key(std::string_view key) {
  for (std::string_view ignored : setting_keys::kIgnoredForeignKeys) {
    if (ignored.back() == '.' ? key.substr(0, ignored.size()) == ignored : key == ignored) return true;
  }
  return false;
}

bool is_section(std::string_view name) {
  return std::find(std::begin(setting_keys::kSections), std::end(setting_keys::kSections), name) !=
         std::end(setting_keys::kSections);
}

std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

std::string suggestion(std::string_view name, bool section_only) {
  const std::string near = nearest_key(name, section_only);
  return near.empty() ? std::string(" (`varslam settings` lists every key)") : fmt::format(" (did you mean {}?)", near);
}

bool equal_ignoring_case(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
         });
}

// The declared spelling (section, key or ORB-SLAM alias) that `name` writes in another case; empty when none.
// Names are case-sensitive, and "Tracking.kernel" would otherwise pass for an ignored ORB-SLAM "Tracking." key.
std::string case_variant(std::string_view name) {
  const auto other_case = [&](std::string_view declared) {
    return declared != name && equal_ignoring_case(name, declared);
  };
  for (std::string_view sec : setting_keys::kSections)
    if (other_case(sec)) return std::string(sec);
  for (const KeySpec& k : setting_keys::all()) {
    if (other_case(k.name)) return std::string(k.name);
    for (std::string_view alias : split(k.aliases, '|'))
      if (other_case(alias)) return std::string(alias);
  }
  return {};
}

[[noreturn]] void unknown(const std::string& loc, std::string_view what, std::string_view name, bool section) {
  if (const std::string right = case_variant(name); !right.empty())
    throw ConfigError(fmt::format("{}: unknown {} '{}': names are case-sensitive; write '{}'", loc, what, name, right));
  throw ConfigError(fmt::format("{}: unknown {} '{}'{}", loc, what, name, suggestion(name, section)));
}

// varslam models a pinhole camera at the image's own resolution; an ORB-SLAM file asking for anything else is
// refused rather than read as a pinhole.
void check_supported_camera(const std::string& key, const YAML::Node& value, const std::string& loc) {
  const std::string v = value.IsScalar() ? value.Scalar() : std::string();
  const bool ok = key == "Camera.type" ? (v == "PinHole" || v == "Rectified") : (as_number(value) == 1.0);
  if (!ok)
    throw ConfigError(fmt::format("{}: key '{}' is {}: varslam supports {} only", loc, key, show(value),
                                  key == "Camera.type" ? "PinHole (or Rectified) cameras" : "Camera.imageScale 1"));
}

std::string location(const std::filesystem::path& file, const YAML::Node& node) {
  const std::string name = file.empty() ? std::string("<settings>") : file.string();
  const auto mark = node.Mark();
  return mark.line >= 0 ? fmt::format("{}:{}", name, mark.line + 1) : name;
}

// Duplicate keys in one map: yaml-cpp keeps both and lookups see the first, so the second would be ignored.
void check_unique_keys(const YAML::Node& map, const std::filesystem::path& file, std::string_view prefix) {
  std::map<std::string, int> seen;
  for (const auto& kv : map) {
    const std::string key = kv.first.Scalar();
    const int line = kv.first.Mark().line + 1;
    if (auto [it, fresh] = seen.emplace(key, line); !fresh)
      throw ConfigError(fmt::format("{}: key '{}{}' appears twice (lines {} and {}); give it once",
                                    location(file, kv.first), prefix, key, it->second, line));
  }
}

// Two spellings of one key ("camera.fx" and ORB-SLAM's "Camera1.fx", or "Camera.fx" beside "Camera1.fx"): only
// one would be read and the other ignored, so the file must say which it means.
void check_one_spelling_per_key(const YAML::Node& root, const std::filesystem::path& file) {
  for (const KeySpec& k : setting_keys::all()) {
    const std::vector<Found> found = spellings_given(root, k);
    if (found.size() < 2) continue;
    const auto line = [](const Found& f) { return f.node.Mark().line + 1; };
    throw ConfigError(fmt::format("{}: '{}' (line {}) and '{}' (line {}) both give {}; give it once",
                                  file.empty() ? std::string("<settings>") : file.string(), found[0].key,
                                  line(found[0]), found[1].key, line(found[1]), k.name));
  }
}

template <typename T>
T convert(const KeySpec& k, const YAML::Node& n);
template <>
int convert<int>(const KeySpec&, const YAML::Node& n) { return static_cast<int>(*as_number(n)); }
template <>
double convert<double>(const KeySpec&, const YAML::Node& n) { return *as_number(n); }
template <>
bool convert<bool>(const KeySpec&, const YAML::Node& n) { return *as_bool(n); }
template <>
std::string convert<std::string>(const KeySpec&, const YAML::Node& n) { return n.Scalar(); }
template <>
std::vector<std::string> convert<std::vector<std::string>>(const KeySpec&, const YAML::Node& n) {
  std::vector<std::string> v;
  for (const auto& item : n) v.push_back(item.Scalar());
  return v;
}
template <>
std::map<std::string, std::string> convert<std::map<std::string, std::string>>(const KeySpec&, const YAML::Node& n) {
  std::map<std::string, std::string> m;
  for (const auto& kv : n) m[kv.first.Scalar()] = kv.second.Scalar();
  return m;
}

template <typename T>
T registry_default(const KeySpec& k);
template <>
int registry_default<int>(const KeySpec& k) { return static_cast<int>(k.number); }
template <>
double registry_default<double>(const KeySpec& k) { return k.number; }
template <>
bool registry_default<bool>(const KeySpec& k) { return k.number != 0.0; }
template <>
std::string registry_default<std::string>(const KeySpec& k) { return std::string(k.text); }
template <>
std::vector<std::string> registry_default<std::vector<std::string>>(const KeySpec& k) {
  std::vector<std::string> v;
  for (std::string_view item : split(k.text, ',')) v.emplace_back(item);
  return v;
}
template <>
std::map<std::string, std::string> registry_default<std::map<std::string, std::string>>(const KeySpec& k) {
  std::map<std::string, std::string> m;
  for (std::string_view pair : split(k.text, ',')) {
    const auto colon = pair.find(':');
    m[std::string(pair.substr(0, colon))] = std::string(pair.substr(colon + 1));
  }
  return m;
}

template <typename T>
constexpr bool matches_type(KeyType t) {
  if constexpr (std::is_same_v<T, int>) return t == KeyType::Int;
  else if constexpr (std::is_same_v<T, double>) return t == KeyType::Real || t == KeyType::Int;
  else if constexpr (std::is_same_v<T, bool>) return t == KeyType::Bool;
  else if constexpr (std::is_same_v<T, std::string>)
    return t == KeyType::Choice || t == KeyType::Text || t == KeyType::Path;
  else if constexpr (std::is_same_v<T, std::vector<std::string>>) return t == KeyType::TextList;
  else return t == KeyType::TextMap;
}

std::string number_text(double v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  return fmt::format("{}", v);
}

}  // namespace

const KeySpec* spec_for_spelling(std::string_view spelled) {
  for (const KeySpec& k : setting_keys::all()) {
    if (k.name == spelled) return &k;
    for (std::string_view alias : split(k.aliases, '|'))
      if (alias == spelled) return &k;
  }
  return nullptr;
}

const KeySpec& key_spec(std::string_view name) {
  if (const KeySpec* k = setting_keys::find(name)) return *k;
  throw std::logic_error(fmt::format("settings key '{}' is not declared in core/setting_keys.hpp", name));
}

template <typename T>
T setting(const Settings& s, std::string_view key) {
  const KeySpec& k = key_spec(key);
  if (!matches_type<T>(k.type))
    throw std::logic_error(fmt::format("settings key '{}' read with another type than declared", key));
  const auto f = find_value(s.root, k);
  if (!f) {
    if (!k.has_default) throw std::logic_error(fmt::format("settings key '{}' has no default", key));
    return registry_default<T>(k);
  }
  check_value(k, f->node, where(s.source, s.overrides, f->node, f->key));
  return convert<T>(k, f->node);
}

template int setting<int>(const Settings&, std::string_view);
template double setting<double>(const Settings&, std::string_view);
template bool setting<bool>(const Settings&, std::string_view);
template std::string setting<std::string>(const Settings&, std::string_view);
template std::vector<std::string> setting<std::vector<std::string>>(const Settings&, std::string_view);
template std::map<std::string, std::string> setting<std::map<std::string, std::string>>(const Settings&,
                                                                                      std::string_view);

bool setting_given(const Settings& s, std::string_view key) { return find_value(s.root, key_spec(key)).has_value(); }

std::optional<double> setting_if_given(const Settings& s, std::string_view key) {
  const KeySpec& k = key_spec(key);
  const auto f = find_value(s.root, k);
  if (!f) return std::nullopt;
  check_value(k, f->node, where(s.source, s.overrides, f->node, f->key));
  return *as_number(f->node);
}

void check_settings_document(const YAML::Node& root, const std::filesystem::path& file,
                             const std::map<std::string, std::string>& overrides) {
  if (!root || root.IsNull()) return;
  if (!root.IsMap())
    throw ConfigError(fmt::format("{}: expected a YAML map of settings at the top level", file.string()));
  check_unique_keys(root, file, "");
  for (const auto& kv : root) {
    const std::string top = kv.first.Scalar();
    const YAML::Node& value = kv.second;
    if (const KeySpec* k = spec_for_spelling(top)) {  // a flat key: ORB-SLAM's "Camera1.fx", or "tracking.kernel"
      if (!value.IsNull()) check_value(*k, value, where(file, overrides, kv.first, top));
      continue;
    }
    if (!case_variant(top).empty()) unknown(location(file, kv.first), "key", top, false);
    if (is_ignored_foreign_key(top)) continue;
    if (top == "Camera.type" || top == "Camera.imageScale") {  // ORB-SLAM keys whose other values we cannot honour
      check_supported_camera(top, value, location(file, kv.first));
      continue;
    }
    if (top.find('.') != std::string::npos) unknown(location(file, kv.first), "key", top, false);
    if (!is_section(top)) {
      if (value.IsMap() || value.IsNull()) unknown(location(file, kv.first), "section", top, true);
      unknown(location(file, kv.first), "key", top, false);
    }
    if (value.IsNull()) continue;  // "semantic:" with nothing under it: the defaults
    if (!value.IsMap())
      throw ConfigError(fmt::format("{}: '{}' must be a map of keys (e.g. {}: {{key: value}}), got {}",
                                    location(file, kv.first), top, top, show(value)));
    check_unique_keys(value, file, top + ".");
    for (const auto& entry : value) {
      const std::string dotted = top + "." + entry.first.Scalar();
      const KeySpec* k = setting_keys::find(dotted);
      const std::string loc = where(file, overrides, entry.first, dotted);
      if (!k) {
        if (auto it = overrides.find(dotted); it != overrides.end()) unknown(it->second, "key", dotted, false);
        unknown(location(file, entry.first), "key", dotted, false);
      }
      if (!entry.second.IsNull()) check_value(*k, entry.second, loc);
    }
  }
  check_one_spelling_per_key(root, file);
}

void apply_setting_overrides(Settings& settings, const std::vector<std::string>& overrides) {
  if (overrides.empty()) return;
  // Built-in defaults have no document yet: start from theirs, so camera/depth/ORB overrides apply too.
  if (settings.source.empty() && (!settings.root || settings.root.IsNull()))
    settings.root = YAML::Load(settings_yaml(settings));
  if (!settings.root || !settings.root.IsMap()) settings.root = YAML::Node(YAML::NodeType::Map);
  for (const std::string& o : overrides) {
    const std::string loc = fmt::format("--set '{}'", o);
    const auto eq = o.find('=');
    const auto dot = o.find('.');
    if (eq == std::string::npos || dot == std::string::npos || dot > eq || dot == 0 || eq == dot + 1)
      throw ConfigError(fmt::format("{}: expected section.key=value (e.g. mapping.kernel=barron-adaptive)", loc));
    const std::string dotted = o.substr(0, eq), value = o.substr(eq + 1);
    const KeySpec* k = setting_keys::find(dotted);
    if (!k) {
      if (!case_variant(dotted).empty()) unknown(loc, "key", dotted, false);
      const auto [section, key] = section_and_key(dotted);
      if (!is_section(section)) unknown(loc, "section", section, true);
      unknown(loc, "key", dotted, false);
    }
    YAML::Node parsed;
    try {
      parsed = YAML::Load(value);
    } catch (const YAML::Exception& e) {
      throw ConfigError(fmt::format("{}: the value is not valid YAML ({})", loc, e.msg));
    }
    if (parsed.IsNull()) throw ConfigError(fmt::format("{}: no value given", loc));
    check_value(*k, parsed, loc);
    const auto [section, key] = section_and_key(dotted);
    YAML::Node sec = settings.root[std::string(section)];
    if (sec && !sec.IsMap() && !sec.IsNull())
      throw ConfigError(fmt::format("{}: settings key '{}' is not a section", loc, section));
    // The override replaces the key in whatever spelling the file gave it, rather than standing beside it.
    settings.root.remove(dotted);
    for (std::string_view alias : split(k->aliases, '|')) settings.root.remove(std::string(alias));
    settings.root[std::string(section)][std::string(key)] = parsed;
    settings.overrides[dotted] = loc;
  }
  // Camera, depth and ORB fields were read when the document was loaded: read them again from the edited one.
  const std::filesystem::path dataset_dir = settings.dataset_dir;
  settings = settings_from_yaml(settings.root, settings.source, settings.overrides);
  settings.dataset_dir = dataset_dir;
}

std::string nearest_key(std::string_view name, bool section_only) {
  // Close enough to be a typo: a third of the name, at least 2 edits (a section typo inside a full key included).
  const std::size_t allowed = std::max<std::size_t>(2, name.size() / 3);
  std::string best;
  std::size_t best_d = SIZE_MAX;
  const auto consider = [&](std::string_view candidate) {
    // The distance is at least the difference in length: a candidate that far off cannot be the answer.
    const std::size_t length_gap = std::max(name.size(), candidate.size()) - std::min(name.size(), candidate.size());
    if (length_gap > allowed) return;
    const std::size_t d = edit_distance(name, candidate);
    if (d < best_d) {
      best_d = d;
      best = std::string(candidate);
    }
  };
  if (section_only) {
    for (std::string_view s : setting_keys::kSections) consider(s);
  } else {
    for (const KeySpec& k : setting_keys::all()) consider(k.name);
  }
  return best_d <= allowed ? best : std::string();
}

std::string default_text(const KeySpec& k) {
  if (!k.has_default) return "(none)";
  switch (k.type) {
    case KeyType::Int:
    case KeyType::Real: return number_text(k.number);
    case KeyType::Bool: return k.number != 0.0 ? "true" : "false";
    case KeyType::TextList: return fmt::format("[{}]", k.text);
    case KeyType::TextMap: {
      std::string out = "{";
      for (std::string_view pair : split(k.text, ',')) {
        const auto colon = pair.find(':');
        out += fmt::format("{}{}: {}", out.size() > 1 ? ", " : "", pair.substr(0, colon), pair.substr(colon + 1));
      }
      return out + "}";
    }
    default: return k.text.empty() ? "\"\"" : std::string(k.text);
  }
}

std::string range_text(const KeySpec& k) {
  switch (k.type) {
    case KeyType::Int:
    case KeyType::Real:
      return fmt::format("{}{}, {}{}", k.lo_open ? "(" : "[", number_text(k.lo), number_text(k.hi),
                         k.hi_open ? ")" : "]");
    case KeyType::Bool: return "true | false";
    case KeyType::Choice: {
      std::string out;
      for (std::string_view c : split(k.choices, '|')) out += (out.empty() ? "" : " | ") + std::string(c);
      return out;
    }
    default: return type_text(k.type);
  }
}

std::string settings_reference_text() {
  std::ostringstream out;
  std::string_view section;
  for (const KeySpec& k : setting_keys::all()) {
    const auto [sec, key] = section_and_key(k.name);
    if (sec != section) {
      out << (section.empty() ? "" : "\n") << sec << ":\n";
      section = sec;
    }
    out << fmt::format("  {:<28} {:<18} {:<28} {}\n", k.name, default_text(k), range_text(k), k.meaning);
    if (!k.aliases.empty()) out << fmt::format("  {:<28} also read as {}\n", "", k.aliases);
  }
  out << "\nORB-SLAM keys accepted with one value: Camera.type (PinHole, Rectified), Camera.imageScale (1)";
  out << "\nORB-SLAM keys accepted and ignored:";
  for (std::string_view i : setting_keys::kIgnoredForeignKeys) out << ' ' << i << (i.back() == '.' ? "*" : "");
  out << "\n";
  return out.str();
}

std::string settings_reference_markdown() {
  std::ostringstream out;
  out << "# varslam settings\n\n"
         "Generated by `varslam settings --markdown` from the settings registry (`src/core/setting_keys.hpp`); "
         "a test keeps this file up to date.\n\n"
         "A settings file is YAML: a map per section (`tracking: {kernel: huber}`), or ORB-SLAM3's flat keys "
         "(`Camera1.fx: 535.4`). Any key can be overridden on the command line: `--set tracking.kernel=huber`. "
         "An unknown section or key, a key given twice (also in two spellings, such as `camera.fx` and "
         "`Camera1.fx`), a name in another case (`Tracking.Kernel`), a value of the wrong type, NaN or a value "
         "outside its range is an error that names the file and line (or the `--set`) and the nearest valid key. "
         "A settings file is one YAML document of at most 1 MiB that expands, through its aliases, to at most "
         "10000 values.\n";
  std::string_view section;
  for (const KeySpec& k : setting_keys::all()) {
    const auto [sec, key] = section_and_key(k.name);
    if (sec != section) {
      out << "\n## " << sec << "\n\n| key | default | valid | meaning |\n|---|---|---|---|\n";
      section = sec;
    }
    std::string meaning(k.meaning);
    if (!k.aliases.empty()) {
      std::string spelled;
      for (std::string_view a : split(k.aliases, '|')) spelled += (spelled.empty() ? "`" : ", `") + std::string(a) + "`";
      meaning += " (ORB-SLAM: " + spelled + ")";
    }
    std::string range = range_text(k);
    std::replace(range.begin(), range.end(), '|', '/');
    out << fmt::format("| `{}` | `{}` | {} | {} |\n", k.name, default_text(k), range, meaning);
  }
  out << "\n## ORB-SLAM keys accepted and ignored\n\n"
         "`Camera.type` (`PinHole` or `Rectified`) and `Camera.imageScale` (`1`) are accepted with those values only: "
         "varslam models a pinhole camera at the image's resolution. These are ignored:\n\n";
  for (std::string_view i : setting_keys::kIgnoredForeignKeys) out << "- `" << i << (i.back() == '.' ? "*" : "") << "`\n";
  return out.str();
}

}  // namespace varslam
