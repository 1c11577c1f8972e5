// What a reader's copy of the dense map costs the fusion: the real kitchen's depth (every 10th frame, at half
// resolution as the dense map keeps it) fused into a 2-cm TSDF one keyframe per iteration, with (range(0) = 1) or
// without (0) a shared copy taken after every keyframe, as the real-time worker does for its readers: the blocks the
// next keyframe writes are copied first. Counter blocks: the volume's size at the end.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "dense/tsdf_volume.hpp"
#include "io/dataset.hpp"
#include "io/settings.hpp"

namespace {

namespace fs = std::filesystem;

struct Views {
  std::vector<varslam::dense::DepthView> views;
};

const Views* kitchen_views() {
  static const Views* v = []() -> Views* {
    const fs::path dir = fs::path(VARSLAM_SHARED_DIR) / "realdata" / "7scenes_redkitchen";
    if (!fs::exists(dir / "rgb.txt")) return nullptr;
    const varslam::Settings settings = varslam::settings_for_dataset(dir, std::nullopt);
    const auto ds = varslam::open_dataset(dir, settings);
    varslam::PinholeCamera half = settings.camera;
    half.width /= 2;
    half.height /= 2;
    half.fx /= 2;
    half.fy /= 2;
    half.cx = (half.cx + 0.5) / 2 - 0.5;
    half.cy = (half.cy + 0.5) / 2 - 0.5;
    auto* out = new Views;
    for (std::size_t i = 0; i < std::min<std::size_t>(400, ds->size()); i += 10) {
      const varslam::RgbdFrame f = ds->load(i);
      varslam::dense::DepthView view;
      cv::resize(f.depth, view.depth, cv::Size(half.width, half.height), 0, 0, cv::INTER_NEAREST);
      cv::resize(f.bgr, view.bgr, cv::Size(half.width, half.height), 0, 0, cv::INTER_AREA);
      view.camera = half;  // every view from the origin: the kitchen's keyframes overlap as much
      out->views.push_back(std::move(view));
    }
    return out;
  }();
  return v;
}

void BM_FuseKeyframes(benchmark::State& state) {
  const Views* k = kitchen_views();
  if (!k) {
    state.SkipWithError("the kitchen sequence (../shared/realdata/7scenes_redkitchen) is not there");
    return;
  }
  const bool share = state.range(0) != 0;
  varslam::dense::TsdfVolume volume{varslam::dense::TsdfConfig{}};
  std::shared_ptr<const varslam::dense::TsdfVolume> reader_copy;
  std::size_t i = 0;
  for (auto _ : state) {
    volume.integrate(k->views[i++ % k->views.size()]);
    if (share) reader_copy = volume.share();
  }
  state.counters["blocks"] = static_cast<double>(volume.block_count());
}
BENCHMARK(BM_FuseKeyframes)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(120)->Repetitions(5);

}  // namespace
BENCHMARK_MAIN();
