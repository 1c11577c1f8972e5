#include "slam/map_snapshot.hpp"

#include <map>
#include <set>
#include <tuple>

#include "slam/keyframe.hpp"
#include "slam/keyframe_database.hpp"
#include "slam/map.hpp"
#include "slam/map_point.hpp"

namespace varslam::slam {

using mapfile::SavedKeyframe;
using mapfile::SavedMapPoint;

SavedMap snapshot_map(const Map& map, const KeyframeDatabase& places, MapFingerprint fingerprint, long next_frame_id) {
  SavedMap out;
  out.fingerprint = std::move(fingerprint);
  out.next_frame_id = next_frame_id;
  std::set<long> kept_kfs;
  const auto keyframes = map.keyframes();
  for (const auto& kf : keyframes)
    if (!kf->is_bad()) kept_kfs.insert(kf->id());
  std::set<long> kept_points;
  for (const auto& mp : map.map_points()) {
    if (mp->is_bad()) continue;
    SavedMapPoint p;
    p.id = mp->id();
    p.first_keyframe_id = std::max(0L, mp->first_keyframe_id());
    p.first_frame_id = std::max(0L, mp->first_frame_id());
    for (const auto& [kf, idx] : mp->observations())
      if (kept_kfs.count(kf->id())) p.observations.emplace_back(kf->id(), idx);
    if (p.observations.empty()) continue;
    const auto ref = mp->reference_keyframe();
    p.reference_keyframe = ref && kept_kfs.count(ref->id()) ? ref->id() : p.observations.front().first;
    p.position = mp->position();
    p.normal = mp->normal();
    p.descriptor = mp->descriptor().clone();
    std::tie(p.min_distance, p.max_distance) = mp->computed_distance_range();
    p.visible = mp->visible();
    p.found = mp->found();
    out.next_map_point_id = std::max(out.next_map_point_id, p.id + 1);
    kept_points.insert(p.id);
    out.map_points.push_back(std::move(p));
  }
  for (const auto& kf : keyframes) {
    if (kf->is_bad()) continue;
    SavedKeyframe k;
    k.id = kf->id();
    k.frame_id = kf->frame_id();
    k.timestamp = kf->timestamp();
    k.segment = kf->segment();
    k.T_cw = kf->pose();
    const FrameFeatures& f = kf->features();
    k.keypoints = f.keypoints;
    k.depth = f.depth;
    k.descriptors = f.descriptors;
    const auto pts = kf->map_points();
    for (std::size_t i = 0; i < pts.size(); ++i)
      if (pts[i] && kept_points.count(pts[i]->id()) && pts[i]->index_in(kf.get()) == static_cast<int>(i))
        k.points.emplace_back(static_cast<int>(i), pts[i]->id());
    const auto parent = kf->parent();
    k.parent = parent && kept_kfs.count(parent->id()) ? parent->id() : -1;
    for (const auto& [other, w] : kf->connections())
      if (kept_kfs.count(other->id())) k.connections.emplace_back(other->id(), w);
    k.signature = places.signature_of(*kf);
    if (k.signature.empty()) k.signature = places.signature(f);
    out.next_keyframe_id = std::max(out.next_keyframe_id, k.id + 1);
    out.next_frame_id = std::max(out.next_frame_id, k.frame_id + 1);
    out.keyframes.push_back(std::move(k));
  }
  return out;
}

void restore_map(const SavedMap& saved, Map& map, KeyframeDatabase& places, std::shared_ptr<const ScaleInfo> scale) {
  std::map<long, KeyFramePtr> kfs;
  for (const auto& k : saved.keyframes) {
    auto f = std::make_shared<FrameFeatures>();
    f->keypoints = k.keypoints;
    f->depth = k.depth;
    f->u_right.assign(k.depth.size(), -1.0f);
    for (std::size_t i = 0; i < k.depth.size(); ++i)
      if (k.depth[i] > 0.0f)
        f->u_right[i] = static_cast<float>(k.keypoints[i].pt.x - saved.fingerprint.camera.bf / k.depth[i]);
    f->descriptors = k.descriptors.clone();
    f->scale = scale;
    f->camera = saved.fingerprint.camera;
    f->close_depth = saved.fingerprint.close_depth;
    f->disparity_weight = saved.fingerprint.disparity_weight;
    f->build_grid();
    Frame frame(k.frame_id, k.timestamp, f);
    frame.T_cw = k.T_cw;
    frame.has_pose = true;
    auto kf = std::make_shared<KeyFrame>(k.id, frame);
    kf->set_segment(k.segment);
    kfs[k.id] = kf;
  }
  for (const auto& p : saved.map_points) {
    auto mp = std::make_shared<MapPoint>(p.id, p.position, kfs.at(p.reference_keyframe), p.first_keyframe_id,
                                         p.first_frame_id);
    for (const auto& [kf_id, idx] : p.observations) {
      const KeyFramePtr& kf = kfs.at(kf_id);
      mp->add_observation(kf, idx, kf->features().has_depth(static_cast<std::size_t>(idx)));
      kf->add_map_point(mp, idx);
    }
    mp->set_descriptor(p.descriptor.clone());
    mp->restore_statistics(p.normal, p.min_distance, p.max_distance, p.visible, p.found);
    map.add_map_point(mp);
  }
  for (const auto& k : saved.keyframes) {
    std::vector<std::pair<KeyFramePtr, int>> connections;
    for (const auto& [id, w] : k.connections) connections.emplace_back(kfs.at(id), w);
    kfs.at(k.id)->restore_graph(connections, k.parent == -1 ? nullptr : kfs.at(k.parent));
    map.add_keyframe(kfs.at(k.id));
    places.add(kfs.at(k.id), k.signature.clone());
  }
  map.continue_ids(saved.next_keyframe_id, saved.next_map_point_id);
}

}  // namespace varslam::slam
