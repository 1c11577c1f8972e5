#include "viewer/viewer_messages.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.hpp"
#include "eval/ate.hpp"

namespace varslam::viewer {
namespace {

std::string floats(const std::vector<float>& v) { return base64(v.data(), v.size() * sizeof(float)); }

std::string ints(const std::vector<std::int32_t>& v) { return base64(v.data(), v.size() * sizeof(std::int32_t)); }

std::string xyz(const std::vector<Eigen::Vector3d>& ps) {
  std::vector<float> v;
  v.reserve(ps.size() * 3);
  for (const auto& p : ps)
    for (int k = 0; k < 3; ++k) v.push_back(static_cast<float>(p[k]));
  return floats(v);
}

std::string edges(const std::vector<std::pair<long, long>>& es) {
  std::vector<std::int32_t> v;
  v.reserve(es.size() * 2);
  for (const auto& [a, b] : es) {
    v.push_back(static_cast<std::int32_t>(a));
    v.push_back(static_cast<std::int32_t>(b));
  }
  return ints(v);
}

void append_pose(std::vector<float>& v, const Eigen::Isometry3d& T) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) v.push_back(static_cast<float>(T.linear()(r, c)));
  for (int k = 0; k < 3; ++k) v.push_back(static_cast<float>(T.translation()[k]));
}

}  // namespace

std::string base64(const void* data, std::size_t bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* p = static_cast<const unsigned char*>(data);
  std::string out;
  out.reserve((bytes + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes; i += 3) {
    const unsigned n = (p[i] << 16) | (p[i + 1] << 8) | p[i + 2];
    out += kAlphabet[(n >> 18) & 63];
    out += kAlphabet[(n >> 12) & 63];
    out += kAlphabet[(n >> 6) & 63];
    out += kAlphabet[n & 63];
  }
  if (i < bytes) {
    const unsigned n = (p[i] << 16) | (i + 1 < bytes ? p[i + 1] << 8 : 0);
    out += kAlphabet[(n >> 18) & 63];
    out += kAlphabet[(n >> 12) & 63];
    out += i + 1 < bytes ? kAlphabet[(n >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string state_name(slam::TrackState s) {
  switch (s) {
    case slam::TrackState::NotInitialized:
      return "initializing";
    case slam::TrackState::Ok:
      return "tracking";
    case slam::TrackState::Lost:
      return "lost";
  }
  return "unknown";
}

nlohmann::json frame_message(const FrameView& f, const cv::Mat& image, int max_width, int jpeg_quality) {
  nlohmann::json j;
  j["index"] = f.index;
  j["t"] = f.timestamp;
  j["state"] = state_name(f.state);
  j["keyframe"] = f.keyframe;
  j["new_segment"] = f.new_segment;
  j["keypoints"] = f.keypoints;
  j["inliers"] = f.inliers;
  j["depth_edge_rejected"] = f.depth_edge_rejected;
  j["fps"] = f.fps;
  j["timings"] = {{"extract_ms", f.timings.extract_ms},
                  {"filter_ms", f.timings.filter_ms},
                  {"match_ms", f.timings.match_ms},
                  {"pose_ms", f.timings.pose_ms},
                  {"track_ms", f.timings.track_ms}};
  j["map_keyframes"] = f.map_keyframes;
  j["map_points"] = f.map_points;
  if (f.T_wc) {
    std::vector<float> pose;
    append_pose(pose, *f.T_wc);
    j["T_wc"] = pose;
  } else {
    j["T_wc"] = nullptr;
  }
  double scale = 1.0;
  if (!image.empty()) {
    cv::Mat shown = image;
    if (image.cols > max_width) {
      scale = static_cast<double>(max_width) / image.cols;
      cv::resize(image, shown, cv::Size(), scale, scale, cv::INTER_AREA);
    }
    std::vector<unsigned char> jpeg;
    cv::imencode(".jpg", shown, jpeg, {cv::IMWRITE_JPEG_QUALITY, jpeg_quality});
    j["image"] = {{"width", shown.cols}, {"height", shown.rows}, {"jpeg", base64(jpeg.data(), jpeg.size())}};
  }
  std::vector<float> marks;
  marks.reserve(f.marks.size() * 3);
  for (const MarkedKeypoint& m : f.marks) {
    marks.push_back(static_cast<float>(m.u * scale));
    marks.push_back(static_cast<float>(m.v * scale));
    marks.push_back(m.mark);
  }
  j["marks"] = floats(marks);
  j["person_filter"] = f.person_filter;
  j["have_detections"] = f.have_detections;
  j["box_age_s"] = f.box_age_s;
  nlohmann::json people = nlohmann::json::array();
  for (const PersonBand& p : f.people)
    people.push_back({{"x", p.box.x * scale},
                      {"y", p.box.y * scale},
                      {"w", p.box.width * scale},
                      {"h", p.box.height * scale},
                      {"depth_m", p.depth_m},
                      {"band_m", p.band_m}});
  j["people"] = people;
  return j;
}

nlohmann::json map_message(const MapView& m) {
  nlohmann::json j;
  std::vector<float> kfs;
  kfs.reserve(m.keyframes.size() * 13);
  for (const KeyframeView& k : m.keyframes) {
    kfs.push_back(static_cast<float>(k.id));
    append_pose(kfs, k.T_wc);
  }
  std::vector<float> pts;
  pts.reserve(m.points.size() * 5);
  for (const PointView& p : m.points) {
    pts.insert(pts.end(), {p.position.x(), p.position.y(), p.position.z(), p.first_keyframe, p.flagged_share});
  }
  j["keyframe_count"] = m.keyframes.size();
  j["point_count"] = m.points.size();
  j["keyframes"] = floats(kfs);
  j["points"] = floats(pts);
  j["covisibility"] = edges(m.covisibility);
  j["spanning_tree"] = edges(m.spanning_tree);
  j["live"] = xyz(m.live);
  j["final_trajectory"] = xyz(m.final_trajectory);
  j["groundtruth"] = xyz(m.groundtruth);
  j["final"] = m.final;
  return j;
}

nlohmann::json dense_region_message(const DenseRegionView& r) {
  const double unit = r.size / 8192;
  std::vector<std::int16_t> xyz;
  std::vector<std::uint8_t> rgb;
  xyz.reserve(r.points.size() * 3);
  rgb.reserve(r.points.size() * 3);
  for (const dense::SurfacePoint& p : r.points) {
    for (int a = 0; a < 3; ++a) {
      const double q = std::round((p.position[a] - r.origin[a]) / unit);
      xyz.push_back(static_cast<std::int16_t>(std::clamp(q, -32768.0, 32767.0)));
    }
    rgb.insert(rgb.end(), p.rgb.begin(), p.rgb.end());
  }
  return {{"key", r.key},
          {"origin", {r.origin.x(), r.origin.y(), r.origin.z()}},
          {"unit", unit},
          {"cell", r.cell},
          {"count", r.points.size()},
          {"xyz", base64(xyz.data(), xyz.size() * sizeof(std::int16_t))},
          {"rgb", base64(rgb.data(), rgb.size())}};
}

std::vector<Eigen::Vector3d> positions(const Trajectory& trajectory) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(trajectory.size());
  for (const StampedPose& p : trajectory) out.push_back(p.T_wc.translation());
  return out;
}

std::vector<Eigen::Vector3d> groundtruth_in_map_frame(const Trajectory& groundtruth, const Trajectory& estimate) {
  if (groundtruth.empty() || estimate.size() < 3) return {};
  try {
    const AteResult ate = evaluate_ate(groundtruth, estimate);
    if (ate.stats.count < 3) return {};
    // alignment: estimate -> ground truth; its inverse brings ground truth into the map's frame.
    const Eigen::Matrix3d Rt = ate.alignment.R.transpose();
    std::vector<Eigen::Vector3d> out;
    out.reserve(groundtruth.size());
    for (const StampedPose& p : groundtruth) out.push_back(Rt * (p.T_wc.translation() - ate.alignment.t));
    return out;
  } catch (const InputError&) {
    return {};
  }
}

}  // namespace varslam::viewer
