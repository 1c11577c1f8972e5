// Detection boxes files ("timestamp label score x y w h"): read or refused with
// InputError; what is read is finite, with non-negative sizes, and the
// nearest-frame lookup finds every stored frame.
#include <cmath>

#include "core/error.hpp"
#include "fuzz_input.hpp"
#include "io/boxes_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace varslam;
  const auto file = fuzz::write_input("boxes.txt", data, size);
  BoxesByTime boxes;
  try {
    boxes = read_boxes_file(file);
  } catch (const InputError&) {
    return 0;
  }
  for (const auto& [t, dets] : boxes) {
    VARSLAM_FUZZ_EXPECT(std::isfinite(t) && !dets.empty());
    for (const auto& d : dets) {
      VARSLAM_FUZZ_EXPECT(std::isfinite(d.score) && std::isfinite(d.box.x) && std::isfinite(d.box.y));
      VARSLAM_FUZZ_EXPECT(std::isfinite(d.box.width) && std::isfinite(d.box.height));
      VARSLAM_FUZZ_EXPECT(d.box.width >= 0 && d.box.height >= 0);
      VARSLAM_FUZZ_EXPECT(!d.label.empty());
    }
    VARSLAM_FUZZ_EXPECT(boxes_near(boxes, t, 0.0).size() == dets.size());
  }
  return 0;
}
