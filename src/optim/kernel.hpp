#pragma once
// Robust kernels shared by every optimiser in this module (Ceres losses and the dedicated IRLS solver
// evaluate the very same function), plus ORB-SLAM's chi-square outlier gates and the adaptive-alpha fit.
#include <cmath>
#include <span>
#include <vector>

#include <ceres/loss_function.h>

#include "robust/barron.hpp"

namespace varslam::optim {

enum class KernelType { None, Huber, BarronFixed, BarronAdaptive };

struct KernelConfig {
  KernelType type = KernelType::Huber;
  double barron_alpha = 1.0;  // BarronFixed (also the starting alpha of BarronAdaptive before any fit)
  double barron_c = 1.0;      // scale on whitened residuals
  double tau = 10.0;          // truncation for the log-partition table (BarronAdaptive)
  double alpha_max = 2.0;     // BarronAdaptive: the fitted alpha is capped here (2 = the grid's top, no cap)
  robust::AlphaFit fit = robust::AlphaFit::ResidualNorm;  // the paper's choice by default
  bool chi2_gates = true;     // ORB-SLAM's outlier gates 5.991 (2 dof) / 7.815 (3 dof) on top of the kernel
};

/// 95% chi-square quantiles ORB-SLAM uses as outlier gates (and, squared-rooted, as Huber deltas).
inline constexpr double kChi2Mono = 5.991;    // 2 dof
inline constexpr double kChi2Stereo = 7.815;  // 3 dof
inline double chi2_threshold(int dof) { return dof == 3 ? kChi2Stereo : kChi2Mono; }

/// The configured kernel at one alpha with its constants precomputed (Huber deltas, Barron's shape): build it
/// once per solve or alpha change, evaluate it per residual. `alpha` is used by both Barron types (fixed or
/// current estimate) and ignored otherwise.
class Kernel {
 public:
  Kernel(const KernelConfig& cfg, double alpha);
  KernelType type() const { return type_; }
  double alpha() const { return barron_.alpha(); }

  /// Kernel on a squared whitened error s, in Ceres' convention: out = {rho(s), rho'(s), rho''(s)}.
  /// `dof` (2 or 3) picks the Huber delta.
  void evaluate(int dof, double s, double out[3]) const {
    switch (type_) {
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
          const double delta = dof == 3 ? delta_stereo_ : delta_mono_;
          out[0] = 2.0 * delta * r - delta2;
          out[1] = delta / r;
          out[2] = -0.5 * out[1] / s;
        }
        return;
      }
      case KernelType::BarronFixed:
      case KernelType::BarronAdaptive:
        barron_.evaluate(s, out);
        return;
    }
  }

 private:
  KernelType type_;
  double delta_mono_, delta_stereo_;
  robust::BarronKernel barron_;
};

/// One-off kernel evaluation (builds a Kernel per call; loops should hold a Kernel instead).
void evaluate_kernel(const KernelConfig& cfg, double alpha, int dof, double s, double out[3]);

/// ceres::LossFunction evaluating a Kernel. The alpha can change between solves (adaptive alternation);
/// it must not change while a solve is running.
class KernelLoss final : public ceres::LossFunction {
 public:
  KernelLoss(const KernelConfig& cfg, int dof, double alpha) : cfg_(cfg), dof_(dof), kernel_(cfg, alpha) {}
  void Evaluate(double s, double out[3]) const override { kernel_.evaluate(dof_, s, out); }
  void set_alpha(double alpha) {
    if (alpha != kernel_.alpha()) kernel_ = Kernel(cfg_, alpha);
  }
  double alpha() const { return kernel_.alpha(); }

 private:
  KernelConfig cfg_;
  int dof_;
  Kernel kernel_;
};

/// Loss for the configured kernel, or nullptr for KernelType::None (plain least squares). Caller owns it.
KernelLoss* make_loss(const KernelConfig& cfg, int dof, double alpha);

/// Alpha to use before any estimate: barron_alpha for the Barron kernels, 2 (L2) otherwise.
inline double initial_alpha(const KernelConfig& cfg) {
  return cfg.type == KernelType::BarronFixed || cfg.type == KernelType::BarronAdaptive ? cfg.barron_alpha : 2.0;
}

/// Collects the samples the alpha fit sees: one whitened residual norm per observation (ResidualNorm) or
/// every whitened component (PerComponent).
class AlphaSamples {
 public:
  explicit AlphaSamples(robust::AlphaFit fit) : fit_(fit) {}
  void clear() { samples_.clear(); }
  void add(std::span<const double> whitened_residual);
  std::span<const double> samples() const { return samples_; }

 private:
  robust::AlphaFit fit_;
  std::vector<double> samples_;
};

struct FittedAlpha {
  double fitted = 2.0;   // the grid search's choice
  double applied = 2.0;  // what the solver uses: fitted, capped at cfg.alpha_max
};

/// Grid-search alpha on the samples with the (cached, per tau) log-partition table. Returns the current
/// alpha unchanged (as both) when there are no samples.
FittedAlpha fit_alpha(const KernelConfig& cfg, std::span<const double> samples, double current_alpha);

}  // namespace varslam::optim
