#pragma once
// Summary statistics of a list of errors, computed the way the TUM benchmark tools print them
// (numpy: population std, median averaging the two middle values of an even count).
#include <cstddef>
#include <vector>

namespace varslam {

struct ErrorStatistics {
  double rmse = 0.0;
  double mean = 0.0;
  double median = 0.0;
  double std = 0.0;  // population standard deviation (numpy.std, ddof = 0)
  double min = 0.0;
  double max = 0.0;
  std::size_t count = 0;
};

/// All zeros with count 0 for an empty list.
ErrorStatistics compute_error_statistics(std::vector<double> errors);

}  // namespace varslam
