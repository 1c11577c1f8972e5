#include "optim/kernel.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>

namespace varslam::optim {

Kernel::Kernel(const KernelConfig& cfg, double alpha)
    : type_(cfg.type),
      delta_mono_(std::sqrt(kChi2Mono)),
      delta_stereo_(std::sqrt(kChi2Stereo)),
      barron_(alpha, cfg.barron_c) {}

void evaluate_kernel(const KernelConfig& cfg, double alpha, int dof, double s, double out[3]) {
  Kernel(cfg, alpha).evaluate(dof, s, out);
}

KernelLoss* make_loss(const KernelConfig& cfg, int dof, double alpha) {
  if (cfg.type == KernelType::None) return nullptr;
  return new KernelLoss(cfg, dof, alpha);
}

void AlphaSamples::add(std::span<const double> e) {
  if (fit_ == robust::AlphaFit::PerComponent) {
    samples_.insert(samples_.end(), e.begin(), e.end());
  } else {
    double s = 0;
    for (double x : e) s += x * x;
    samples_.push_back(std::sqrt(s));
  }
}

namespace {
// Building a table integrates ~120 densities: do it once per tau for the whole process.
const robust::LogPartitionTable& table_for(double tau) {
  static std::mutex mutex;
  static std::map<double, std::unique_ptr<robust::LogPartitionTable>> tables;
  const std::lock_guard<std::mutex> lock(mutex);
  auto& slot = tables[tau];
  if (!slot) slot = std::make_unique<robust::LogPartitionTable>(tau);
  return *slot;
}
}  // namespace

FittedAlpha fit_alpha(const KernelConfig& cfg, std::span<const double> samples, double current_alpha) {
  if (samples.empty()) return {current_alpha, current_alpha};
  const double fitted = robust::estimate_alpha(samples, table_for(cfg.tau), cfg.barron_c).alpha;
  return {fitted, std::min(cfg.alpha_max, fitted)};
}

}  // namespace varslam::optim
