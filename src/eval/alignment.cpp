#include "eval/alignment.hpp"

#include <Eigen/SVD>
#include <stdexcept>

namespace varslam {

Eigen::Isometry3d Alignment::apply(const Eigen::Isometry3d& T) const {
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = R * T.linear();
  out.translation() = apply(Eigen::Vector3d(T.translation()));
  return out;
}

Alignment align_point_sets(const Eigen::Matrix3Xd& model, const Eigen::Matrix3Xd& data, bool with_scale) {
  if (model.cols() != data.cols()) throw std::invalid_argument("align_point_sets: point counts differ");
  if (model.cols() < 2) throw std::invalid_argument("align_point_sets: need at least 2 point pairs");
  const double n = static_cast<double>(model.cols());
  const Eigen::Vector3d mu_model = model.rowwise().mean();
  const Eigen::Vector3d mu_data = data.rowwise().mean();
  const Eigen::Matrix3Xd mc = model.colwise() - mu_model;
  const Eigen::Matrix3Xd dc = data.colwise() - mu_data;

  // Cross-covariance data * model^T; its SVD U D V^T gives R = U S V^T with S fixing a reflection.
  const Eigen::Matrix3d sigma = dc * mc.transpose() / n;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(sigma, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) S(2, 2) = -1.0;

  Alignment a;
  a.R = svd.matrixU() * S * svd.matrixV().transpose();
  if (with_scale) {
    const double model_variance = mc.squaredNorm() / n;
    if (model_variance <= 0.0) throw std::invalid_argument("align_point_sets: model points all coincide");
    a.scale = (svd.singularValues().asDiagonal() * S).trace() / model_variance;
  }
  a.t = mu_data - a.scale * a.R * mu_model;
  return a;
}

}  // namespace varslam
