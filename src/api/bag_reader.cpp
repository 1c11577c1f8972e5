// varslam::BagReader: the public face of the bag dataset (bag/bag_dataset.hpp).
#include <varslam/bag.hpp>

#include "api/config_access.hpp"
#include "bag/bag_dataset.hpp"
#include "io/trajectory_io.hpp"

namespace varslam {

struct BagReader::Impl {
  Config config;
  std::unique_ptr<Dataset> dataset;
};

BagReader::BagReader(const std::string& file, const BagTopics& topics, const std::string& settings_file)
    : impl_(std::make_unique<Impl>()) {
  bag::BagTopics t{topics.rgb, topics.depth, topics.info, topics.gt_frame};
  std::optional<std::filesystem::path> sfile;
  if (!settings_file.empty()) sfile = settings_file;
  Settings s = bag::settings_for_bag(file, sfile, t);
  impl_->dataset = bag::open_bag_dataset(file, s, t);
  impl_->config = detail::ConfigAccess::wrap(std::move(s));
}

BagReader::~BagReader() = default;

const Config& BagReader::config() const { return impl_->config; }

std::size_t BagReader::size() const { return impl_->dataset->size(); }

BagFrame BagReader::frame(std::size_t i) const {
  if (i >= size())
    throw InputError(impl_->dataset->root().string() + ": frame " + std::to_string(i) + " of " +
                     std::to_string(size()));
  RgbdFrame f = impl_->dataset->load(i);
  return {f.timestamp, f.bgr, f.depth};
}

std::vector<TimedPose> BagReader::groundtruth() const {
  std::vector<TimedPose> out;
  const auto file = impl_->dataset->groundtruth();
  if (!file) return out;
  for (const StampedPose& p : read_tum_trajectory(*file)) {
    const Eigen::Quaterniond q(p.T_wc.rotation());
    const Eigen::Vector3d t = p.T_wc.translation();
    out.push_back({p.timestamp, {{t.x(), t.y(), t.z()}, {q.x(), q.y(), q.z(), q.w()}}});
  }
  return out;
}

bool BagReader::supported() { return bag::bag_support_built(); }

}  // namespace varslam
