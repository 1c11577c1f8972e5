// Settings files, both layouts (ours and ORB-SLAM's, with or without OpenCV's
// %YAML:1.0 header): a file is read or refused with InputError; what is read
// writes back out and reads again to the same values. Reading or refusing takes
// under a second: a few kilobytes that take longer (nested aliases) are a
// finding, whatever libFuzzer's -timeout is.
#include <chrono>
#include <cmath>

#include "core/error.hpp"
#include "fuzz_input.hpp"
#include "io/settings.hpp"

namespace {

// Guards the read: leaving its scope (the file read or refused) more than a second after entering it breaks the
// contract.
struct TimedRead {
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  ~TimedRead() {
    if (std::chrono::steady_clock::now() - start > std::chrono::seconds(1))
      varslam::fuzz::contract_broken("reading the settings took more than a second");
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace varslam;
  const auto file = fuzz::write_input("settings.yaml", data, size);
  Settings s;
  try {
    const TimedRead timed;
    s = load_settings(file);
  } catch (const InputError&) {
    return 0;
  }
  VARSLAM_FUZZ_EXPECT(std::isfinite(s.camera.fx) && s.camera.fx > 0);
  VARSLAM_FUZZ_EXPECT(s.camera.width > 0 && s.camera.height > 0);
  VARSLAM_FUZZ_EXPECT(std::isfinite(s.depth_factor) && s.depth_factor > 0);
  VARSLAM_FUZZ_EXPECT(s.orb.n_features > 0 && s.orb.n_levels > 0);

  const auto again = fuzz::scratch_dir() / "settings_again.yaml";
  save_settings(s, again);
  const Settings t = load_settings(again);
  VARSLAM_FUZZ_EXPECT(t.camera.fx == s.camera.fx && t.camera.width == s.camera.width);
  VARSLAM_FUZZ_EXPECT(t.depth_factor == s.depth_factor && t.orb.n_features == s.orb.n_features);
  return 0;
}
