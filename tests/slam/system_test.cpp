// slam::System across threads: an exception on the mapping thread reaches the caller with its message.
#include "slam/system.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

#include "io/dataset.hpp"
#include "slam/e2e_support.hpp"

namespace varslam::slam {
namespace {

class SystemError : public ::testing::TestWithParam<RunMode> {};

// In either mode the error reaches the caller with its message, and every later frame reports it again: the map
// is no longer consistent.
TEST_P(SystemError, MappingErrorReachesTheCallerAndStopsMapping) {
  synth::SynthConfig sc;
  sc.scenario = "static";
  sc.seconds = 4.0;
  sc.seed = 7;
  const auto seq = e2e::cached_sequence("static_seq", sc);  // end_to_end_test's: its runs make Local BAs
  const Settings settings = settings_for_dataset(seq, std::nullopt);
  SlamConfig cfg = slam_config_from(settings);
  auto ds = open_dataset(seq, settings);
  std::string message;
  int local_bas = 0;
  cfg.mapping.ba_observer = [&local_bas](const PinholeCamera&, const optim::BaProblem&, const optim::BaConfig&) {
    if (++local_bas == 2) throw std::runtime_error("local BA exploded");
  };
  try {
    System system(cfg, settings.camera, settings.close_depth_m(), GetParam());
    std::size_t i = 0;
    try {
      for (; i < ds->size(); ++i) system.process(ds->load(i));
      system.finish();
    } catch (const std::runtime_error& e) {
      message = e.what();
    }
    ASSERT_LT(i + 1, ds->size());
    EXPECT_THROW(system.process(ds->load(i + 1)), std::runtime_error);
    EXPECT_THROW(system.finish(), std::runtime_error);
  } catch (const std::runtime_error& e) {
    ADD_FAILURE() << "unexpected: " << e.what();
  }
  EXPECT_EQ(message, "local BA exploded");
  EXPECT_EQ(local_bas, 2);  // mapping stopped at the error
}

INSTANTIATE_TEST_SUITE_P(BothModes, SystemError, ::testing::Values(RunMode::Deterministic, RunMode::RealTime));

}  // namespace
}  // namespace varslam::slam
