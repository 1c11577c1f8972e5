// Minimal varslam user: reads colour and 16-bit depth PNGs of the same names from FOLDER/rgb and FOLDER/depth
// (file names are the timestamps, e.g. 1311870436.796000.png), runs the full system with the person filter
// (YOLO when its model is found: set VARSLAM_MODELS) and prints one TUM pose line per tracked frame.
//   rgbd_folder FOLDER [SETTINGS.yaml]
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <varslam/varslam.hpp>

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: rgbd_folder FOLDER [SETTINGS.yaml]\n";
    return 2;
  }
  const fs::path folder = argv[1];
  try {
    varslam::Settings settings = varslam::load_settings(argc > 2 ? fs::path(argv[2]) : folder / "settings.yaml");
    varslam::Slam slam(settings);  // semantic.detector defaults to auto: YOLO when the model is found
    std::vector<fs::path> images;
    for (const auto& e : fs::directory_iterator(folder / "rgb")) images.push_back(e.path());
    std::sort(images.begin(), images.end());
    for (const fs::path& rgb : images) {
      const cv::Mat bgr = cv::imread(rgb.string(), cv::IMREAD_COLOR);
      const cv::Mat depth = cv::imread((folder / "depth" / rgb.filename()).string(), cv::IMREAD_UNCHANGED);
      const double t = std::stod(rgb.stem().string());
      const varslam::FrameResult r = slam.track(bgr, depth, t);
      if (!r.T_wc) continue;
      const Eigen::Vector3d p = r.T_wc->translation();
      const Eigen::Quaterniond q(r.T_wc->rotation());
      std::printf("%.6f %.5f %.5f %.5f %.6f %.6f %.6f %.6f\n", t, p.x(), p.y(), p.z(), q.x(), q.y(), q.z(), q.w());
    }
    slam.finish();
    const varslam::SlamSummary s = slam.summary();
    std::cerr << s.tracked << " of " << s.frames << " frames tracked, " << s.keyframes << " keyframes, person filter: "
              << s.detector << "\n";
    return s.tracked > 0 ? 0 : 1;
  } catch (const std::exception& e) {
    std::cerr << "rgbd_folder: " << e.what() << "\n";
    return 2;
  }
}
