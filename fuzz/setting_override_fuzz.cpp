// `--set section.key=value` overrides, one per input line, on the default
// settings: applied or refused with InputError naming the override.
#include <cmath>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "fuzz_input.hpp"
#include "io/settings.hpp"
#include "io/settings_registry.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace varslam;
  std::vector<std::string> overrides(1);
  for (std::size_t i = 0; i < size; ++i) {
    if (data[i] == '\n')
      overrides.emplace_back();
    else
      overrides.back().push_back(static_cast<char>(data[i]));
  }
  Settings s = default_settings();
  try {
    apply_setting_overrides(s, overrides);
  } catch (const InputError&) {
    return 0;
  }
  VARSLAM_FUZZ_EXPECT(std::isfinite(s.camera.fx) && s.camera.fx > 0);
  VARSLAM_FUZZ_EXPECT(std::isfinite(s.depth_factor) && s.depth_factor > 0);
  VARSLAM_FUZZ_EXPECT(s.orb.n_features > 0 && s.orb.n_levels > 0);
  return 0;
}
