#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "optim/ba_problem_io.hpp"
#include "optim/synthetic_problems.hpp"

namespace varslam::optim {
namespace {

namespace fs = std::filesystem;

fs::path temp_file(const std::string& name) { return fs::temp_directory_path() / ("varslam_ba_io_" + name); }

RecordedBaProblem recorded() {
  SyntheticBaOptions opt;
  opt.points = 50;
  RecordedBaProblem r{PinholeCamera{}, make_synthetic_ba(PinholeCamera{}, opt).initial, BaConfig{}};
  r.camera.fx = 531.5;
  r.config.kernel.type = KernelType::BarronAdaptive;
  r.config.kernel.alpha_max = 1.0;
  r.config.iterations = 3;
  return r;
}

TEST(BaProblemIo, ARecordedProblemReadsBackAsItWasAndSolvesTheSame) {
  const RecordedBaProblem r = recorded();
  const fs::path file = temp_file("roundtrip.lba");
  write_ba_problem(file, r);
  const RecordedBaProblem back = read_ba_problem(file);
  fs::remove(file);
  EXPECT_EQ(back.camera.fx, 531.5);
  EXPECT_EQ(back.config.kernel.type, KernelType::BarronAdaptive);
  EXPECT_EQ(back.config.kernel.alpha_max, 1.0);
  EXPECT_EQ(back.config.iterations, 3);
  ASSERT_EQ(back.problem.observations.size(), r.problem.observations.size());
  ASSERT_EQ(back.problem.keyframes.size(), r.problem.keyframes.size());
  for (std::size_t k = 0; k < r.problem.keyframes.size(); ++k) {
    EXPECT_TRUE(back.problem.keyframes[k].T_cw.isApprox(r.problem.keyframes[k].T_cw, 1e-15));
    EXPECT_EQ(back.problem.keyframes[k].fixed, r.problem.keyframes[k].fixed);
  }
  EXPECT_EQ(back.problem.points, r.problem.points);
  BaProblem a = r.problem, b = back.problem;
  const BaResult ra = solve_local_ba(r.camera, a, r.config), rb = solve_local_ba(back.camera, b, back.config);
  EXPECT_NEAR(ra.final_cost, rb.final_cost, 1e-9 * ra.final_cost);  // the pose goes through a quaternion
  EXPECT_EQ(ra.outlier_observation, rb.outlier_observation);
}

TEST(BaProblemIo, ADamagedFileIsAnErrorNamingItAndTheProblem) {
  const fs::path file = temp_file("damaged.lba");
  write_ba_problem(file, recorded());
  const auto expect_error = [&](const std::string& part) {
    try {
      read_ba_problem(file);
      ADD_FAILURE() << "no error; expected one saying " << part;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
    }
  };
  fs::resize_file(file, fs::file_size(file) - 10);
  expect_error("truncated");
  {
    std::ofstream(file, std::ios::binary) << "not a problem at all, just text";
  }
  expect_error("header");
  fs::remove(file);
  expect_error("cannot be opened");
}

}  // namespace
}  // namespace varslam::optim
