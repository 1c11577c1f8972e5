// TUM / OpenLORIS list files ("timestamp path"): read or refused with
// InputError; what is read has finite, strictly increasing timestamps, and
// association with itself pairs every entry with itself.
#include <cmath>

#include "core/error.hpp"
#include "fuzz_input.hpp"
#include "io/frame_list.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace varslam;
  const auto file = fuzz::write_input("rgb.txt", data, size);
  std::vector<ListEntry> list;
  try {
    list = read_frame_list(file);
  } catch (const InputError&) {
    return 0;
  }
  for (std::size_t i = 0; i < list.size(); ++i) {
    VARSLAM_FUZZ_EXPECT(std::isfinite(list[i].timestamp));
    VARSLAM_FUZZ_EXPECT(!list[i].path.empty());
    if (i > 0) VARSLAM_FUZZ_EXPECT(list[i].timestamp > list[i - 1].timestamp);
  }
  const auto pairs = associate_frames(list, list);
  VARSLAM_FUZZ_EXPECT(pairs.size() == list.size());
  for (const auto& p : pairs) VARSLAM_FUZZ_EXPECT(p.rgb.timestamp == p.depth.timestamp);
  return 0;
}
