// Saved map files: read or refused with InputError; what is read holds together
// (every reference names a record of the file) and encodes back to a file that
// reads the same.
#include "core/error.hpp"
#include "fuzz_input.hpp"
#include "mapfile/map_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace varslam;
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  mapfile::SavedMap m;
  try {
    m = mapfile::decode_map(bytes, "fuzz.map");
  } catch (const InputError&) {
    return 0;
  }
  VARSLAM_FUZZ_EXPECT(!m.keyframes.empty());
  const std::string again = mapfile::encode_map(m);
  const mapfile::SavedMap m2 = mapfile::decode_map(again, "again.map");
  VARSLAM_FUZZ_EXPECT(m2.keyframes.size() == m.keyframes.size() && m2.map_points.size() == m.map_points.size());
  VARSLAM_FUZZ_EXPECT(mapfile::encode_map(m2) == again);
  return 0;
}
