#include "synth/large_box.hpp"

#include <algorithm>
#include <cmath>

namespace varslam::synth {

namespace {

// The generator's camera (PinholeCamera defaults): 640 x 480 pixels, focal length 525.
constexpr double kFocal = 525.0, kImageArea = 640.0 * 480.0, kHalfViewTan = 320.0 / 525.0;
constexpr double kHeightShare = 0.85;  // box height / edge, as rendered
// How fast the box's anchor follows the camera: slow enough to drop the hand-held shake, fast enough that the
// box keeps its distance while the camera walks.
constexpr double kFollowSeconds = 0.3;

double smoothstep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3 - 2 * x);
}

double wrap_angle(double a) { return std::atan2(std::sin(a), std::cos(a)); }

double heading_of(const Eigen::Isometry3d& T_wc) {
  const Eigen::Vector3d f = T_wc.rotation().col(2);
  return std::atan2(f.x(), f.z());
}

Eigen::Vector3d horizontal_offset(double yaw, const Eigen::Vector3d& local) {
  const Eigen::Vector3d forward(std::sin(yaw), 0, std::cos(yaw));
  const Eigen::Vector3d right = Eigen::Vector3d::UnitY().cross(forward);
  return local.x() * right + local.y() * Eigen::Vector3d::UnitY() + local.z() * forward;
}

struct Phase {
  enum Kind { Enter, HoldIn, Carried, HoldOut, Exit } kind;
  double u;  // progress through the phase, 0..1
};

Phase phase_of(const LargeBoxEpisode& e, double tau) {
  const double carried_start = e.enter_s + e.hold_in_s;
  const double exit_start = e.length - e.exit_s;
  const double carried_end = exit_start - e.hold_out_s;
  if (tau < e.enter_s) return {Phase::Enter, tau / e.enter_s};
  if (tau < carried_start) return {Phase::HoldIn, 0};
  if (tau < carried_end) return {Phase::Carried, (tau - carried_start) / std::max(1e-9, carried_end - carried_start)};
  if (tau < exit_start) return {Phase::HoldOut, 0};
  return {Phase::Exit, (tau - exit_start) / e.exit_s};
}

// Where the box sits relative to its anchor (x right, y down, z forward) and its extra yaw, per phase.
struct LocalPose {
  Eigen::Vector3d offset;
  double yaw = 0;
};

LocalPose local_pose(const LargeBoxEpisode& e, const Phase& ph, int sway_cycles) {
  // Far enough to the side that no part of the box is in view.
  const double out_of_view = kHalfViewTan * (e.distance + e.size) + e.size / 2 + 0.2;
  LocalPose p;
  p.offset = {0, e.lift_m, e.distance + e.size / 2};
  switch (ph.kind) {
    case Phase::Enter: p.offset.x() = e.enter_side * out_of_view * (1 - smoothstep(ph.u)); break;
    case Phase::Exit: p.offset.x() = e.exit_side * out_of_view * smoothstep(ph.u); break;
    case Phase::Carried: {
      // Every term is zero at both ends of the phase, so the box rests exactly where a hold leaves it.
      const double s = std::sin(M_PI * sway_cycles * ph.u);
      p.offset.x() = e.sway_m * s;
      p.offset.z() += 0.08 * std::sin(2 * M_PI * ph.u);
      p.offset.y() += 0.03 * std::sin(4 * M_PI * ph.u);
      p.yaw = 0.12 * s;
      break;
    }
    case Phase::HoldIn:
    case Phase::HoldOut: break;
  }
  return p;
}

void fit_phases(LargeBoxEpisode& e) {
  // Enter, holds and exit take at most 70 % of the episode; the carried part gets the rest.
  const double fixed = e.enter_s + e.hold_in_s + e.hold_out_s + e.exit_s;
  const double budget = 0.7 * e.length;
  if (fixed > budget) {
    const double k = budget / fixed;
    e.enter_s *= k;
    e.hold_in_s *= k;
    e.hold_out_s *= k;
    e.exit_s *= k;
  }
}

// Computes the track; returns the first time (since the episode start) at which a held box is closer to the
// walking camera than kMinHeldDistance, or a negative value when it never is.
constexpr double kMinHeldDistance = 0.5;

double compute_track(LargeBoxEpisode& e, const std::function<Eigen::Isometry3d(double)>& pose_at, int sway_cycles) {
  const Eigen::Isometry3d T0 = pose_at(e.start);
  Eigen::Vector3d anchor = T0.translation();
  double anchor_yaw = heading_of(T0);
  const int n = static_cast<int>(std::ceil(e.length / LargeBoxEpisode::kTrackStep)) + 1;
  e.track.clear();
  e.track.reserve(static_cast<std::size_t>(n));
  const double gain = LargeBoxEpisode::kTrackStep / kFollowSeconds;
  for (int i = 0; i < n; ++i) {
    const double tau = std::min(e.length, i * LargeBoxEpisode::kTrackStep);
    const Phase ph = phase_of(e, tau);
    const bool held = ph.kind == Phase::HoldIn || ph.kind == Phase::HoldOut;
    if (!held && i > 0) {
      const Eigen::Isometry3d T = pose_at(e.start + tau);
      anchor += gain * (T.translation() - anchor);
      anchor_yaw = wrap_angle(anchor_yaw + gain * wrap_angle(heading_of(T) - anchor_yaw));
    }
    const LocalPose lp = local_pose(e, ph, sway_cycles);
    const Eigen::Vector3d c = anchor + horizontal_offset(anchor_yaw, lp.offset);
    e.track.emplace_back(c.x(), c.y(), c.z(), wrap_angle(anchor_yaw + lp.yaw));
    if (held && (pose_at(e.start + tau).inverse() * c).z() - e.size / 2 < kMinHeldDistance) return tau;
  }
  return -1.0;
}

// Someone holding a box still does not let the camera walk into it: a hold ends where the camera comes too close.
void compute_track_with_short_enough_holds(LargeBoxEpisode& e, const std::function<Eigen::Isometry3d(double)>& pose_at,
                                           int sway_cycles) {
  for (int attempt = 0; attempt < 4; ++attempt) {
    const double too_close = compute_track(e, pose_at, sway_cycles);
    if (too_close < 0) return;
    const double hold_in_end = e.enter_s + e.hold_in_s;
    if (too_close <= hold_in_end)
      e.hold_in_s = std::max(0.0, too_close - e.enter_s - 0.1);
    else
      e.hold_out_s = std::max(0.0, too_close - (e.length - e.exit_s - e.hold_out_s) - 0.1);
  }
  e.hold_in_s = e.hold_out_s = 0;
  compute_track(e, pose_at, sway_cycles);
}

}  // namespace

Eigen::Isometry3d LargeBoxEpisode::pose_at(double t) const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (track.empty()) return T;
  const double x = std::clamp((t - start) / kTrackStep, 0.0, static_cast<double>(track.size() - 1));
  const auto i = static_cast<std::size_t>(x);
  const std::size_t j = std::min(i + 1, track.size() - 1);
  const double w = x - static_cast<double>(i);
  const Eigen::Vector4d& a = track[i];
  const Eigen::Vector4d& b = track[j];
  T.translation() = (1 - w) * a.head<3>() + w * b.head<3>();
  const double yaw = a.w() + w * wrap_angle(b.w() - a.w());
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()).toRotationMatrix();
  return T;
}

nlohmann::json LargeBoxEpisode::describe() const {
  return {{"start_s", start},          {"length_s", length},       {"size_m", size},
          {"distance_m", distance},    {"coverage", coverage},     {"enter_side", enter_side < 0 ? "left" : "right"},
          {"exit_side", exit_side < 0 ? "left" : "right"},         {"enter_s", enter_s},
          {"hold_in_s", hold_in_s},    {"hold_out_s", hold_out_s}, {"exit_s", exit_s},
          {"sway_m", sway_m}};
}

std::vector<LargeBoxEpisode> plan_large_box_episodes(double duration,
                                                     const std::function<Eigen::Isometry3d(double)>& pose_at,
                                                     std::mt19937_64& rng) {
  auto uni = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  auto coin = [&] { return uni(0, 1) < 0.5; };
  std::vector<LargeBoxEpisode> out;
  const int count = duration >= 12.0 ? 2 : 1;
  const double slot = (duration - 1.0) / count;
  for (int k = 0; k < count; ++k) {
    LargeBoxEpisode e;
    if (count == 1) {
      e.start = 0.15 * duration;
      e.length = 0.75 * duration;
    } else {
      e.start = 1.0 + k * slot + uni(0.3, 1.0);
      e.length = std::min(uni(6.0, 8.5), 1.0 + (k + 1) * slot - 0.5 - e.start);
    }
    e.distance = uni(0.6, 1.5);
    // Edge from the share of the image to cover (near face at `distance`), within what someone can carry.
    const double wanted = uni(0.27, 0.61);
    e.size = std::clamp(e.distance / kFocal * std::sqrt(wanted * kImageArea / kHeightShare), 0.35, 1.3);
    e.coverage = std::min(1.0, kHeightShare * std::pow(e.size * kFocal / e.distance, 2) / kImageArea);
    e.enter_side = coin() ? -1 : 1;
    e.exit_side = coin() ? -1 : 1;
    e.enter_s = uni(0.5, 1.5);
    e.exit_s = coin() ? uni(0.4, 0.8) : uni(1.0, 2.0);  // a fast exit is where tracking is most at risk
    e.hold_in_s = coin() ? 0.0 : uni(1.0, 2.5);
    e.hold_out_s = coin() ? 0.0 : uni(1.0, 2.5);
    e.sway_m = uni(0.03, 0.2);
    e.lift_m = uni(-0.1, 0.2);
    const int sway_cycles = 1 + static_cast<int>(uni(0, 2.99));
    fit_phases(e);
    compute_track_with_short_enough_holds(e, pose_at, sway_cycles);
    out.push_back(std::move(e));
  }
  return out;
}

}  // namespace varslam::synth
