#include "optim/kernel.hpp"

#include <cmath>
#include <map>
#include <memory>
#include <mutex>

namespace varslam::optim {

void evaluate_kernel(const KernelConfig& cfg, double alpha, int dof, double s, double out[3]) {
  switch (cfg.type) {
    case KernelType::None:
      out[0] = s;
      out[1] = 1.0;
      out[2] = 0.0;
      return;
    case KernelType::Huber: {
      // Huber on the whitened norm with delta^2 = the chi2 gate (ORB-SLAM3's choice).
      const double delta2 = chi2_threshold(dof);
      if (s <= delta2) {
        out[0] = s;
        out[1] = 1.0;
        out[2] = 0.0;
      } else {
        const double r = std::sqrt(s);
        const double delta = std::sqrt(delta2);
        out[0] = 2.0 * delta * r - delta2;
        out[1] = delta / r;
        out[2] = -0.5 * out[1] / s;
      }
      return;
    }
    case KernelType::BarronFixed:
    case KernelType::BarronAdaptive:
      robust::barron_kernel(s, alpha, cfg.barron_c, out);
      return;
  }
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

double fit_alpha(const KernelConfig& cfg, std::span<const double> samples, double current_alpha) {
  if (samples.empty()) return current_alpha;
  return robust::estimate_alpha(samples, table_for(cfg.tau), cfg.barron_c).alpha;
}

}  // namespace varslam::optim
