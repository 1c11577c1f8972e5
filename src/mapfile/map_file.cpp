#include "mapfile/map_file.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "core/error.hpp"
#include "features/descriptor_matching.hpp"
#include "io/atomic_file.hpp"

namespace varslam::mapfile {
namespace {

using json = nlohmann::json;

// Bounds a well-formed map stays far inside; beyond them a file is garbage, and
// reading on would allocate for it.
constexpr std::size_t kMaxKeypointsPerKeyframe = 100000;
constexpr double kMaxCoordinate = 1e6;  // metres
constexpr double kRotationTolerance = 1e-6;

std::uint32_t crc32_of(const std::vector<std::uint8_t>& bytes) {
  uLong crc = crc32(0L, Z_NULL, 0);
  // zlib takes at most 4 GiB per call; maps are far below that, but feed it in
  // chunks anyway.
  constexpr std::size_t kChunk = 1u << 30;
  for (std::size_t off = 0; off < bytes.size(); off += kChunk)
    crc = crc32(crc, bytes.data() + off, static_cast<uInt>(std::min(kChunk, bytes.size() - off)));
  return static_cast<std::uint32_t>(crc);
}

json::binary_t mat_bytes(const cv::Mat& m) {
  const cv::Mat c = m.isContinuous() ? m : m.clone();
  return json::binary_t(std::vector<std::uint8_t>(c.datastart, c.dataend));
}

json pose_json(const Eigen::Isometry3d& T) {
  json a = json::array();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) a.push_back(T.matrix()(r, c));
  return a;
}

json camera_json(const PinholeCamera& c) {
  return {{"fx", c.fx}, {"fy", c.fy}, {"cx", c.cx}, {"cy", c.cy},       {"k1", c.k1},         {"k2", c.k2},
          {"p1", c.p1}, {"p2", c.p2}, {"k3", c.k3}, {"width", c.width}, {"height", c.height}, {"bf", c.bf}};
}

json keyframe_json(const SavedKeyframe& k) {
  json xs = json::array(), ys = json::array(), sizes = json::array(), angles = json::array(), responses = json::array(),
       octaves = json::array(), depth = json::array();
  for (const auto& kp : k.keypoints) {
    xs.push_back(kp.pt.x);
    ys.push_back(kp.pt.y);
    sizes.push_back(kp.size);
    angles.push_back(kp.angle);
    responses.push_back(kp.response);
    octaves.push_back(kp.octave);
  }
  for (float d : k.depth) depth.push_back(d);
  json points = json::array(), connections = json::array();
  for (const auto& [idx, id] : k.points) points.push_back({idx, id});
  for (const auto& [id, w] : k.connections) connections.push_back({id, w});
  return {{"id", k.id},
          {"frame_id", k.frame_id},
          {"timestamp", k.timestamp},
          {"segment", k.segment},
          {"T_cw", pose_json(k.T_cw)},
          {"keypoints",
           {{"x", xs}, {"y", ys}, {"size", sizes}, {"angle", angles}, {"response", responses}, {"octave", octaves}}},
          {"depth", depth},
          {"descriptors", mat_bytes(k.descriptors)},
          {"points", points},
          {"parent", k.parent},
          {"connections", connections},
          {"signature", mat_bytes(k.signature)}};
}

json map_point_json(const SavedMapPoint& p) {
  json obs = json::array();
  for (const auto& [id, idx] : p.observations) obs.push_back({id, idx});
  return {{"id", p.id},
          {"first_keyframe_id", p.first_keyframe_id},
          {"first_frame_id", p.first_frame_id},
          {"reference_keyframe", p.reference_keyframe},
          {"position", {p.position.x(), p.position.y(), p.position.z()}},
          {"normal", {p.normal.x(), p.normal.y(), p.normal.z()}},
          {"descriptor", mat_bytes(p.descriptor)},
          {"distance_range", {p.min_distance, p.max_distance}},
          {"visible", p.visible},
          {"found", p.found},
          {"observations", obs}};
}

// A nested array or object per level costs the CBOR reader a stack frame: a
// hostile file of a million nested arrays would overflow the stack. Maps nest 6
// deep; a first pass refuses anything deeper than this.
constexpr std::size_t kMaxNesting = 16;

class NestingCheck final : public json::json_sax_t {
 public:
  bool null() override { return true; }
  bool boolean(bool) override { return true; }
  bool number_integer(number_integer_t) override { return true; }
  bool number_unsigned(number_unsigned_t) override { return true; }
  bool number_float(number_float_t, const string_t&) override { return true; }
  bool string(string_t&) override { return true; }
  bool binary(binary_t&) override { return true; }
  bool start_object(std::size_t) override { return ++depth_ <= kMaxNesting; }
  bool key(string_t&) override { return true; }
  bool end_object() override { return --depth_, true; }
  bool start_array(std::size_t) override { return ++depth_ <= kMaxNesting; }
  bool end_array() override { return --depth_, true; }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception&) override { return false; }
  bool too_deep() const { return depth_ > kMaxNesting; }

 private:
  std::size_t depth_ = 0;
};

template <typename It>
json parse_cbor(It begin, It end, const std::string& what, const char* part) {
  NestingCheck check;
  if (!json::sax_parse(begin, end, &check, json::input_format_t::cbor)) {
    if (check.too_deep())
      throw InputError(fmt::format("{}: corrupted map {} (nested deeper than {} levels)", what, part, kMaxNesting));
    throw InputError(fmt::format("{}: truncated or corrupted map {}", what, part));
  }
  try {
    return json::from_cbor(begin, end);
  } catch (const json::exception& e) {
    throw InputError(fmt::format("{}: truncated or corrupted map {} ({})", what, part, e.what()));
  }
}

// ---- decoding: every field through one checked accessor, so a message always
// names the field ----

class Reader {
 public:
  explicit Reader(std::string what) : what_(std::move(what)) {}

  [[noreturn]] void fail(const std::string& where, const std::string& problem) const {
    throw InputError(fmt::format("{}: not a usable map: {}: {}", what_, where, problem));
  }

  const json& field(const json& obj, const char* key, const std::string& where) const {
    if (!obj.is_object()) fail(where, "expected an object");
    const auto it = obj.find(key);
    if (it == obj.end()) fail(where, fmt::format("missing field '{}'", key));
    return *it;
  }
  const json& array(const json& obj, const char* key, const std::string& where) const {
    const json& a = field(obj, key, where);
    if (!a.is_array()) fail(where + "." + key, "expected an array");
    return a;
  }
  double real(const json& v, const std::string& where) const {
    if (!v.is_number()) fail(where, "expected a number");
    const double d = v.get<double>();
    if (!std::isfinite(d)) fail(where, "not finite");
    return d;
  }
  double real(const json& obj, const char* key, const std::string& where) const {
    return real(field(obj, key, where), where + "." + key);
  }
  long integer(const json& v, const std::string& where, long lo, long hi) const {
    if (!v.is_number_integer()) fail(where, "expected an integer");
    // Unsigned values above the signed range would wrap: compare before
    // converting.
    if (v.is_number_unsigned() && v.get<std::uint64_t>() > static_cast<std::uint64_t>(hi))
      fail(where, fmt::format("out of range [{}, {}]", lo, hi));
    const long x = v.get<long>();
    if (x < lo || x > hi) fail(where, fmt::format("{} out of range [{}, {}]", x, lo, hi));
    return x;
  }
  long integer(const json& obj, const char* key, const std::string& where, long lo, long hi) const {
    return integer(field(obj, key, where), where + "." + key, lo, hi);
  }
  std::string text(const json& obj, const char* key, const std::string& where) const {
    const json& v = field(obj, key, where);
    if (!v.is_string()) fail(where + "." + key, "expected a string");
    return v.get<std::string>();
  }
  const std::vector<std::uint8_t>& bytes(const json& obj, const char* key, const std::string& where) const {
    const json& v = field(obj, key, where);
    if (!v.is_binary()) fail(where + "." + key, "expected a byte string");
    return v.get_binary();
  }
  /// rows x 32 descriptor bytes.
  cv::Mat descriptors(const json& obj, const char* key, const std::string& where, std::size_t rows) const {
    const auto& b = bytes(obj, key, where);
    if (b.size() != rows * kDescriptorBytes)
      fail(where + "." + key, fmt::format("{} bytes, expected {} x {}", b.size(), rows, kDescriptorBytes));
    cv::Mat m(static_cast<int>(rows), kDescriptorBytes, CV_8U);
    if (!b.empty()) std::memcpy(m.data, b.data(), b.size());
    return m;
  }
  Eigen::Vector3d vector3(const json& obj, const char* key, const std::string& where, double bound) const {
    const json& a = array(obj, key, where);
    if (a.size() != 3) fail(where + "." + key, "expected 3 numbers");
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i) {
      v[i] = real(a[i], where + "." + key);
      if (std::abs(v[i]) > bound) fail(where + "." + key, fmt::format("{} beyond {:g}", v[i], bound));
    }
    return v;
  }
  Eigen::Isometry3d pose(const json& obj, const char* key, const std::string& where) const {
    const json& a = array(obj, key, where);
    if (a.size() != 12) fail(where + "." + key, "expected 12 numbers (3 x 4, row-major)");
    Eigen::Matrix4d M = Eigen::Matrix4d::Identity();
    for (int i = 0; i < 12; ++i) M(i / 4, i % 4) = real(a[i], where + "." + key);
    const Eigen::Matrix3d R = M.topLeftCorner<3, 3>();
    if ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > kRotationTolerance ||
        R.determinant() < 0)
      fail(where + "." + key, "not a rotation");
    if (M.topRightCorner<3, 1>().cwiseAbs().maxCoeff() > kMaxCoordinate)
      fail(where + "." + key, fmt::format("translation beyond {:g} m", kMaxCoordinate));
    Eigen::Isometry3d T;
    T.matrix() = M;
    return T;
  }
  /// Pairs [a, b] of integers.
  std::vector<std::pair<long, long>> pairs(const json& obj, const char* key, const std::string& where) const {
    std::vector<std::pair<long, long>> out;
    const json& a = array(obj, key, where);
    out.reserve(a.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
      const std::string w = fmt::format("{}.{}[{}]", where, key, i);
      if (!a[i].is_array() || a[i].size() != 2) fail(w, "expected a pair");
      out.emplace_back(integer(a[i][0], w, 0, std::numeric_limits<int>::max()),
                       integer(a[i][1], w, 0, std::numeric_limits<int>::max()));
    }
    return out;
  }

 private:
  std::string what_;
};

PinholeCamera read_camera(const Reader& r, const json& c) {
  PinholeCamera cam;
  const std::string w = "fingerprint.camera";
  cam.fx = r.real(c, "fx", w);
  cam.fy = r.real(c, "fy", w);
  cam.cx = r.real(c, "cx", w);
  cam.cy = r.real(c, "cy", w);
  cam.k1 = r.real(c, "k1", w);
  cam.k2 = r.real(c, "k2", w);
  cam.p1 = r.real(c, "p1", w);
  cam.p2 = r.real(c, "p2", w);
  cam.k3 = r.real(c, "k3", w);
  cam.width = static_cast<int>(r.integer(c, "width", w, 1, 100000));
  cam.height = static_cast<int>(r.integer(c, "height", w, 1, 100000));
  cam.bf = r.real(c, "bf", w);
  if (cam.fx <= 0 || cam.fy <= 0) r.fail(w, "focal length not positive");
  return cam;
}

SavedKeyframe read_keyframe(const Reader& r, const json& j, std::size_t i, int n_levels) {
  const std::string w = fmt::format("keyframes[{}]", i);
  SavedKeyframe k;
  constexpr long kMaxId = std::numeric_limits<int>::max();
  k.id = r.integer(j, "id", w, 0, kMaxId);
  k.frame_id = r.integer(j, "frame_id", w, 0, kMaxId);
  k.timestamp = r.real(j, "timestamp", w);
  k.segment = static_cast<int>(r.integer(j, "segment", w, 1, kMaxId));
  k.T_cw = r.pose(j, "T_cw", w);
  const json& kp = r.field(j, "keypoints", w);
  const std::string wk = w + ".keypoints";
  const json& xs = r.array(kp, "x", wk);
  const std::size_t n = xs.size();
  if (n > kMaxKeypointsPerKeyframe) r.fail(wk, fmt::format("{} keypoints (at most {})", n, kMaxKeypointsPerKeyframe));
  const json* cols[6] = {&xs,
                         &r.array(kp, "y", wk),
                         &r.array(kp, "size", wk),
                         &r.array(kp, "angle", wk),
                         &r.array(kp, "response", wk),
                         &r.array(kp, "octave", wk)};
  for (const json* c : cols)
    if (c->size() != n) r.fail(wk, "columns of different lengths");
  k.keypoints.resize(n);
  for (std::size_t q = 0; q < n; ++q) {
    cv::KeyPoint& p = k.keypoints[q];
    p.pt.x = static_cast<float>(r.real((*cols[0])[q], wk + ".x"));
    p.pt.y = static_cast<float>(r.real((*cols[1])[q], wk + ".y"));
    p.size = static_cast<float>(r.real((*cols[2])[q], wk + ".size"));
    p.angle = static_cast<float>(r.real((*cols[3])[q], wk + ".angle"));
    p.response = static_cast<float>(r.real((*cols[4])[q], wk + ".response"));
    p.octave = static_cast<int>(r.integer((*cols[5])[q], wk + ".octave", 0, n_levels - 1));
    if (std::abs(p.pt.x) > 1e5 || std::abs(p.pt.y) > 1e5) r.fail(wk, "keypoint far outside any image");
  }
  const json& depth = r.array(j, "depth", w);
  if (depth.size() != n) r.fail(w + ".depth", fmt::format("{} values for {} keypoints", depth.size(), n));
  k.depth.resize(n);
  for (std::size_t q = 0; q < n; ++q) {
    const double d = r.real(depth[q], w + ".depth");
    if (d > kMaxCoordinate) r.fail(w + ".depth", "beyond any sensor");
    k.depth[q] = static_cast<float>(d);
  }
  k.descriptors = r.descriptors(j, "descriptors", w, n);
  for (const auto& [idx, id] : r.pairs(j, "points", w)) {
    if (static_cast<std::size_t>(idx) >= n) r.fail(w + ".points", fmt::format("keypoint {} of {}", idx, n));
    k.points.emplace_back(static_cast<int>(idx), id);
  }
  const json& parent = r.field(j, "parent", w);
  k.parent = parent.is_number_integer() && parent.get<long>() == -1 ? -1 : r.integer(parent, w + ".parent", 0, kMaxId);
  for (const auto& [id, weight] : r.pairs(j, "connections", w))
    k.connections.emplace_back(id, static_cast<int>(weight));
  const auto& sig = r.bytes(j, "signature", w);
  if (sig.size() % kDescriptorBytes != 0) r.fail(w + ".signature", "not whole descriptors");
  k.signature = r.descriptors(j, "signature", w, sig.size() / kDescriptorBytes);
  return k;
}

SavedMapPoint read_map_point(const Reader& r, const json& j, std::size_t i) {
  const std::string w = fmt::format("map_points[{}]", i);
  constexpr long kMaxId = std::numeric_limits<int>::max();
  SavedMapPoint p;
  p.id = r.integer(j, "id", w, 0, kMaxId);
  p.first_keyframe_id = r.integer(j, "first_keyframe_id", w, 0, kMaxId);
  p.first_frame_id = r.integer(j, "first_frame_id", w, 0, kMaxId);
  p.reference_keyframe = r.integer(j, "reference_keyframe", w, 0, kMaxId);
  p.position = r.vector3(j, "position", w, kMaxCoordinate);
  p.normal = r.vector3(j, "normal", w, 1.0 + 1e-6);
  p.descriptor = r.descriptors(j, "descriptor", w, 1);
  const json& range = r.array(j, "distance_range", w);
  if (range.size() != 2) r.fail(w + ".distance_range", "expected 2 numbers");
  p.min_distance = r.real(range[0], w + ".distance_range");
  p.max_distance = r.real(range[1], w + ".distance_range");
  if (p.min_distance < 0 || p.max_distance < p.min_distance) r.fail(w + ".distance_range", "not a range");
  p.visible = static_cast<int>(r.integer(j, "visible", w, 0, kMaxId));
  p.found = static_cast<int>(r.integer(j, "found", w, 0, kMaxId));
  for (const auto& [id, idx] : r.pairs(j, "observations", w)) p.observations.emplace_back(id, static_cast<int>(idx));
  if (p.observations.empty()) r.fail(w + ".observations", "a map point nobody observes");
  return p;
}

// References between records: each must name a record of the file, and both
// sides of an observation must agree.
void check_references(const Reader& r, const SavedMap& m) {
  std::map<long, const SavedKeyframe*> kfs;
  std::map<long, const SavedMapPoint*> pts;
  for (const auto& k : m.keyframes)
    if (!kfs.emplace(k.id, &k).second) r.fail("keyframes", fmt::format("id {} appears twice", k.id));
  for (const auto& p : m.map_points)
    if (!pts.emplace(p.id, &p).second) r.fail("map_points", fmt::format("id {} appears twice", p.id));
  std::set<std::pair<long, int>> kf_side;  // (keyframe id, keypoint index) of each keyframe -> point link
  for (const auto& k : m.keyframes) {
    const std::string w = fmt::format("keyframe {}", k.id);
    if (k.id >= m.next_keyframe_id) r.fail(w, "id not below next_keyframe_id");
    if (k.frame_id >= m.next_frame_id) r.fail(w, "frame id not below next_frame_id");
    if (k.parent != -1 && !kfs.count(k.parent)) r.fail(w, fmt::format("parent {} is not in the map", k.parent));
    if (k.parent == k.id) r.fail(w, "its own parent");
    for (const auto& [id, weight] : k.connections)
      if (!kfs.count(id) || id == k.id) r.fail(w, fmt::format("connection to keyframe {} not in the map", id));
    std::set<int> used;
    for (const auto& [idx, id] : k.points) {
      if (!pts.count(id)) r.fail(w, fmt::format("map point {} is not in the map", id));
      if (!used.insert(idx).second) r.fail(w, fmt::format("keypoint {} linked twice", idx));
      kf_side.emplace(k.id, idx);
    }
  }
  // The spanning tree must be a tree: each parent chain ends. A chain is walked only up to a keyframe already
  // known to reach the root, so a long chain costs its length once, not once per keyframe on it.
  std::set<long> reaches_root;
  for (const auto& k : m.keyframes) {
    std::set<long> chain;
    for (long id = k.id; id != -1 && !reaches_root.count(id); id = kfs.at(id)->parent)
      if (!chain.insert(id).second) r.fail(fmt::format("keyframe {}", k.id), "its parent chain loops back");
    reaches_root.insert(chain.begin(), chain.end());
  }
  std::size_t links = 0;
  for (const auto& p : m.map_points) {
    const std::string w = fmt::format("map point {}", p.id);
    if (p.id >= m.next_map_point_id) r.fail(w, "id not below next_map_point_id");
    if (!kfs.count(p.reference_keyframe)) r.fail(w, "reference keyframe not in the map");
    std::set<long> seen;
    for (const auto& [kf, idx] : p.observations) {
      if (!kfs.count(kf) || !seen.insert(kf).second) r.fail(w, fmt::format("observation in keyframe {}", kf));
      if (!kf_side.count({kf, idx})) r.fail(w, fmt::format("keyframe {} keypoint {} does not link back", kf, idx));
      ++links;
    }
  }
  if (links != kf_side.size()) r.fail("map_points", "keyframes link points that do not observe them back");
  // The links agree as sets; check they agree on which point, too.
  std::map<std::pair<long, int>, long> kf_point;
  for (const auto& k : m.keyframes)
    for (const auto& [idx, id] : k.points) kf_point[{k.id, idx}] = id;
  for (const auto& p : m.map_points)
    for (const auto& [kf, idx] : p.observations)
      if (kf_point.at({kf, idx}) != p.id) r.fail(fmt::format("map point {}", p.id), "observation links another point");
  // Parents form a forest: walking up from any keyframe ends at a root.
  for (const auto& k : m.keyframes) {
    long at = k.id;
    for (std::size_t steps = 0; at != -1; ++steps) {
      if (steps > m.keyframes.size()) r.fail(fmt::format("keyframe {}", k.id), "spanning tree has a cycle");
      at = kfs.at(at)->parent;
    }
  }
}

}  // namespace

std::string encode_map(const SavedMap& m) {
  const MapFingerprint& f = m.fingerprint;
  json content = {{"fingerprint",
                   {{"camera", camera_json(f.camera)},
                    {"n_levels", f.n_levels},
                    {"scale_factor", f.scale_factor},
                    {"close_depth", f.close_depth},
                    {"disparity_weight", f.disparity_weight},
                    {"settings_yaml", f.settings_yaml},
                    {"created_by", f.created_by}}},
                  {"next_keyframe_id", m.next_keyframe_id},
                  {"next_map_point_id", m.next_map_point_id},
                  {"next_frame_id", m.next_frame_id},
                  {"keyframes", json::array()},
                  {"map_points", json::array()}};
  if (m.groundtruth_alignment) content["groundtruth_alignment"] = pose_json(*m.groundtruth_alignment);
  for (const auto& k : m.keyframes) content["keyframes"].push_back(keyframe_json(k));
  for (const auto& p : m.map_points) content["map_points"].push_back(map_point_json(p));
  const std::vector<std::uint8_t> body = json::to_cbor(content);
  const json outer = {{"format", "varslam map"},
                      {"version", kMapFormatVersion},
                      {"crc32", crc32_of(body)},
                      {"content", json::binary_t(body)}};
  const std::vector<std::uint8_t> bytes = json::to_cbor(outer);
  std::string out(kMapMagic, sizeof kMapMagic);
  out.append(bytes.begin(), bytes.end());
  return out;
}

SavedMap decode_map(const std::string& bytes, const std::string& what) {
  const Reader r(what);
  if (bytes.size() < sizeof kMapMagic || std::memcmp(bytes.data(), kMapMagic, sizeof kMapMagic) != 0)
    throw InputError(fmt::format("{}: not a varslam map (no 'VSLAMMAP' magic at its start)", what));
  const json outer = parse_cbor(bytes.begin() + sizeof kMapMagic, bytes.end(), what, "file");
  const long version = r.integer(outer, "version", "header", 0, std::numeric_limits<int>::max());
  if (version != kMapFormatVersion)
    throw InputError(
        fmt::format("{}: map format version {}, this varslam "
                    "reads version {} (save the map again with "
                    "the varslam that will load it)",
                    what, version, kMapFormatVersion));
  const auto& body = r.bytes(outer, "content", "header");
  const long crc = r.integer(outer, "crc32", "header", 0, 0xffffffffL);
  if (crc32_of(body) != static_cast<std::uint32_t>(crc))
    throw InputError(fmt::format("{}: corrupted map file (checksum of its content does not match)", what));
  const json c = parse_cbor(body.begin(), body.end(), what, "content");
  SavedMap m;
  const json& fp = r.field(c, "fingerprint", "content");
  m.fingerprint.camera = read_camera(r, r.field(fp, "camera", "fingerprint"));
  m.fingerprint.n_levels = static_cast<int>(r.integer(fp, "n_levels", "fingerprint", 1, 32));
  m.fingerprint.scale_factor = r.real(fp, "scale_factor", "fingerprint");
  m.fingerprint.close_depth = r.real(fp, "close_depth", "fingerprint");
  m.fingerprint.disparity_weight = r.real(fp, "disparity_weight", "fingerprint");
  m.fingerprint.settings_yaml = r.text(fp, "settings_yaml", "fingerprint");
  m.fingerprint.created_by = r.text(fp, "created_by", "fingerprint");
  if (m.fingerprint.scale_factor <= 1.0 || m.fingerprint.scale_factor > 4.0)
    r.fail("fingerprint.scale_factor", "outside (1, 4]");
  constexpr long kMaxId = std::numeric_limits<int>::max();
  m.next_keyframe_id = r.integer(c, "next_keyframe_id", "content", 0, kMaxId);
  m.next_map_point_id = r.integer(c, "next_map_point_id", "content", 0, kMaxId);
  m.next_frame_id = r.integer(c, "next_frame_id", "content", 0, kMaxId);
  if (c.contains("groundtruth_alignment")) m.groundtruth_alignment = r.pose(c, "groundtruth_alignment", "content");
  const json& kfs = r.array(c, "keyframes", "content");
  for (std::size_t i = 0; i < kfs.size(); ++i)
    m.keyframes.push_back(read_keyframe(r, kfs[i], i, m.fingerprint.n_levels));
  const json& pts = r.array(c, "map_points", "content");
  for (std::size_t i = 0; i < pts.size(); ++i) m.map_points.push_back(read_map_point(r, pts[i], i));
  if (m.keyframes.empty()) r.fail("keyframes", "a map without keyframes");
  check_references(r, m);
  return m;
}

void save_map_file(const SavedMap& map, const std::filesystem::path& file) {
  write_file_atomically(file, encode_map(map), "map");
}

SavedMap load_map_file(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec))
    throw InputError(fmt::format("{}: map file not found", file.string()));
  std::ifstream in(file, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  if (!in) throw InputError(fmt::format("{}: cannot read the map file", file.string()));
  return decode_map(ss.str(), file.string());
}

double intrinsics_difference(const PinholeCamera& a, const PinholeCamera& b) {
  return std::max({std::abs(a.fx - b.fx) / b.fx, std::abs(a.fy - b.fy) / b.fy, std::abs(a.cx - b.cx) / b.width,
                   std::abs(a.cy - b.cy) / b.height});
}

void check_map_compatible(const MapFingerprint& map, const PinholeCamera& camera, int n_levels, double scale_factor,
                          const std::string& what) {
  const PinholeCamera& m = map.camera;
  if (m.width != camera.width || m.height != camera.height)
    throw InputError(fmt::format("{}: the map was built with a {}x{} camera, this run's camera is {}x{}", what, m.width,
                                 m.height, camera.width, camera.height));
  // Two calibrations of one sensor differ by a few percent at most (self-calibration here: about 1 %); beyond 10 %
  // it is another sensor or a wrong settings file.
  constexpr double kSameSensor = 0.01, kAnotherSensor = 0.10;
  const double difference = intrinsics_difference(camera, m);
  if (difference > kAnotherSensor)
    throw InputError(
        fmt::format("{}: the map was built with another camera "
                    "(fx fy cx cy = {} {} {} {}; this run's: "
                    "{} {} {} {}; {:.0f} % apart, at most 10 %)",
                    what, m.fx, m.fy, m.cx, m.cy, camera.fx, camera.fy, camera.cx, camera.cy, 100 * difference));
  if (difference > kSameSensor)
    spdlog::warn("{}: the map was built with fx fy cx cy = {} {} {} {}; this run's intrinsics, {} {} {} {} ({:.1f} % "
                 "apart), are the ones used",
                 what, m.fx, m.fy, m.cx, m.cy, camera.fx, camera.fy, camera.cx, camera.cy, 100 * difference);
  if (map.n_levels != n_levels || std::abs(map.scale_factor - scale_factor) > 1e-9)
    throw InputError(
        fmt::format("{}: the map was built with an ORB pyramid of "
                    "{} levels x {}, this run's is {} x {} "
                    "(orb.n_levels, orb.scale_factor)",
                    what, map.n_levels, map.scale_factor, n_levels, scale_factor));
}

}  // namespace varslam::mapfile
