#pragma once
// Local BA problems as files: the benchmark replays problems recorded from a real run, so that the solver's cost
// is tracked on the same inputs from one commit to the next (bench/local_ba_bench.cpp, bench/data/local_ba/).
#include <filesystem>

#include "core/camera.hpp"
#include "optim/local_ba.hpp"

namespace varslam::optim {

/// One recorded solve: what solve_local_ba was given (the observer is not recorded).
struct RecordedBaProblem {
  PinholeCamera camera;
  BaProblem problem;
  BaConfig config;
};

/// Writes `r` to `path` in the versioned binary format of docs/ba_problem_format.md (little-endian).
/// Throws std::runtime_error naming the file when it cannot be written.
void write_ba_problem(const std::filesystem::path& path, const RecordedBaProblem& r);

/// Reads a file written by write_ba_problem. Throws std::runtime_error naming the file and the problem on a
/// missing file, another format or version, a truncated file or indices out of range.
RecordedBaProblem read_ba_problem(const std::filesystem::path& path);

}  // namespace varslam::optim
