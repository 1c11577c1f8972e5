#pragma once
// The live map as a saved map's plain records and back (the file itself:
// mapfile/map_file.hpp).
#include <memory>

#include "mapfile/map_file.hpp"
#include "slam/frame.hpp"

namespace varslam::slam {

class Map;
class KeyframeDatabase;

using mapfile::MapFingerprint;
using mapfile::SavedMap;

/// The live map as plain records (keyframes and points that are not bad; links
/// to culled keyframes dropped).
SavedMap snapshot_map(const Map& map, const KeyframeDatabase& places, MapFingerprint fingerprint, long next_frame_id);

/// Builds keyframes and points from the records into `map` (which must be
/// empty) and `places`; new keyframes and points get ids after the loaded ones.
void restore_map(const SavedMap& saved, Map& map, KeyframeDatabase& places, std::shared_ptr<const ScaleInfo> scale);

}  // namespace varslam::slam
