// associations.txt ("t_rgb rgb_path t_depth depth_path"): read or refused with
// InputError; what is read has finite, strictly increasing colour timestamps
// and finite depth timestamps.
#include <cmath>

#include "core/error.hpp"
#include "fuzz_input.hpp"
#include "io/frame_list.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace varslam;
  const auto file = fuzz::write_input("associations.txt", data, size);
  std::vector<FramePair> pairs;
  try {
    pairs = read_associations(file);
  } catch (const InputError&) {
    return 0;
  }
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    VARSLAM_FUZZ_EXPECT(std::isfinite(pairs[i].rgb.timestamp) && std::isfinite(pairs[i].depth.timestamp));
    VARSLAM_FUZZ_EXPECT(!pairs[i].rgb.path.empty() && !pairs[i].depth.path.empty());
    if (i > 0) VARSLAM_FUZZ_EXPECT(pairs[i].rgb.timestamp > pairs[i - 1].rgb.timestamp);
  }
  return 0;
}
