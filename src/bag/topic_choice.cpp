#include "bag/topic_choice.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <optional>

#include "core/error.hpp"

namespace varslam::bag {
namespace {

constexpr char kImage[] = "sensor_msgs/Image";
constexpr char kCompressed[] = "sensor_msgs/CompressedImage";
constexpr char kCameraInfo[] = "sensor_msgs/CameraInfo";

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

bool has(const std::string& name, std::initializer_list<const char*> words) {
  const std::string l = lower(name);
  return std::any_of(words.begin(), words.end(), [&](const char* w) { return l.find(w) != std::string::npos; });
}

bool is_image(const TopicEntry& t) { return t.type == kImage || t.type == kCompressed; }
bool is_depth(const TopicEntry& t) { return has(t.name, {"depth"}); }
// Streams that are images but neither colour nor depth (RealSense and OpenLORIS record them beside).
bool is_other_stream(const TopicEntry& t) {
  return has(t.name, {"infra", "/ir/", "/ir_", "fisheye", "confidence", "thermal", "mask", "label", "semantic"});
}

int colour_rank(const TopicEntry& t) {
  return (has(t.name, {"rgb", "color", "colour"}) ? 4 : 0) + (t.type == kCompressed ? -2 : 0) +
         (has(t.name, {"image_color", "image_raw", "image_rect_color", "image/data"}) ? 1 : 0);
}

int depth_rank(const TopicEntry& t) {
  return (has(t.name, {"aligned", "registered"}) ? 4 : 0) + (t.type == kCompressed ? -2 : 0) +
         (has(t.name, {"/image", "image_raw", "image/data", "image_rect"}) ? 1 : 0);
}

std::string list_topics(const std::vector<TopicEntry>& topics) {
  std::string s;
  for (const auto& t : topics) s += fmt::format("\n  {} ({}, {} messages)", t.name, t.type, t.messages);
  return s.empty() ? std::string(" (none)") : s;
}

// The best-ranked candidate; an error naming `option` when two share the best rank.
template <typename Rank>
std::optional<std::string> best(const std::string& bag, const std::vector<const TopicEntry*>& cands, Rank rank,
                                const char* what, const char* option) {
  if (cands.empty()) return std::nullopt;
  int top = rank(*cands[0]);
  for (const auto* c : cands) top = std::max(top, rank(*c));
  std::vector<std::string> tied;
  for (const auto* c : cands)
    if (rank(*c) == top) tied.push_back(c->name);
  if (tied.size() > 1)
    throw InputError(fmt::format("{}: {} topics {} could all be the {}; choose one with {}", bag, tied.size(),
                                 fmt::join(tied, ", "), what, option));
  return tied.front();
}

const TopicEntry& named(const std::string& bag, const std::vector<TopicEntry>& topics, const std::string& name,
                        const char* option) {
  for (const auto& t : topics)
    if (t.name == name) return t;
  throw InputError(
      fmt::format("{}: {} {} is not in the bag; its topics are:{}", bag, option, name, list_topics(topics)));
}

std::size_t shared_components(const std::string& a, const std::string& b) {
  std::size_t n = 0, i = 0;
  while (i < a.size() && i < b.size() && a[i] == b[i]) {
    if (a[i] == '/' && i > 0) ++n;
    ++i;
  }
  return n;
}

}  // namespace

ChosenTopics choose_topics(const std::string& bag, const std::vector<TopicEntry>& topics, const std::string& rgb,
                           const std::string& depth, const std::string& info) {
  std::vector<const TopicEntry*> colour, depths, infos;
  for (const auto& t : topics) {
    if (t.type == kCameraInfo) infos.push_back(&t);
    if (!is_image(t) || is_other_stream(t)) continue;
    (is_depth(t) ? depths : colour).push_back(&t);
  }
  if (colour.empty() && depths.empty() && rgb.empty())
    throw InputError(fmt::format("{}: no image topic (sensor_msgs/Image or CompressedImage); its topics are:{}", bag,
                                 list_topics(topics)));
  ChosenTopics out;
  for (auto [given, chosen, option] :
       {std::tuple{&rgb, &out.rgb, "--topic-rgb"}, std::tuple{&depth, &out.depth, "--topic-depth"}}) {
    if (given->empty()) continue;
    const TopicEntry& t = named(bag, topics, *given, option);
    if (!is_image(t))
      throw InputError(fmt::format("{}: {} {} is a {}, not an image topic (sensor_msgs/Image or CompressedImage)", bag,
                                   option, *given, t.type));
    *chosen = *given;
  }
  if (out.rgb.empty()) {
    auto c = best(bag, colour, colour_rank, "colour images", "--topic-rgb");
    if (!c)
      throw InputError(
          fmt::format("{}: no colour image topic (only depth); choose one with --topic-rgb; its topics "
                      "are:{}",
                      bag, list_topics(topics)));
    out.rgb = *c;
  }
  if (out.depth.empty()) {
    auto d = best(bag, depths, depth_rank, "depth images", "--topic-depth");
    if (!d)
      throw InputError(
          fmt::format("{}: no depth image topic (a topic with 'depth' in its name); choose one with "
                      "--topic-depth; its topics are:{}",
                      bag, list_topics(topics)));
    out.depth = *d;
  }
  if (out.rgb == out.depth) throw InputError(fmt::format("{}: colour and depth are the same topic {}", bag, out.rgb));
  if (!info.empty()) {
    const TopicEntry& t = named(bag, topics, info, "--topic-info");
    if (t.type != kCameraInfo)
      throw InputError(fmt::format("{}: --topic-info {} is a {}, not a {}", bag, info, t.type, kCameraInfo));
    out.info = info;
  } else if (!infos.empty()) {
    // The CameraInfo beside the colour topic: the one sharing the most leading name components with it.
    auto rank = [&](const TopicEntry& t) { return static_cast<int>(shared_components(t.name, out.rgb)); };
    if (auto i = best(bag, infos, rank, "colour camera's CameraInfo", "--topic-info")) out.info = *i;
  }
  for (const auto& t : topics)
    if (has(t.name, {"depth units", "depth_units"}) && (t.type == "std_msgs/Float32" || t.type == "std_msgs/Float64"))
      out.depth_units = t.name;
  return out;
}

}  // namespace varslam::bag
