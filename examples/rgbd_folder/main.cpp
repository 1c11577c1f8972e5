// Minimal varslam user: reads colour and 16-bit depth PNGs of the same names from FOLDER/rgb and FOLDER/depth
// (file names are the timestamps, e.g. 1311870436.796000.png), runs the full system with the person filter
// (YOLO when its model is found: set VARSLAM_MODELS) and prints one TUM pose line per tracked frame. C++17.
//   rgbd_folder FOLDER [SETTINGS.yaml]
#include <algorithm>
#include <cstdio>
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
    const varslam::Config config =
        varslam::Config::from_file(argc > 2 ? std::string(argv[2]) : (folder / "settings.yaml").string());
    varslam::Slam slam(config);  // semantic.detector defaults to auto: YOLO when the model is found
    std::vector<fs::path> images;
    for (const auto& e : fs::directory_iterator(folder / "rgb")) images.push_back(e.path());
    std::sort(images.begin(), images.end());
    for (const fs::path& rgb : images) {
      const cv::Mat bgr = cv::imread(rgb.string(), cv::IMREAD_COLOR);
      const cv::Mat depth = cv::imread((folder / "depth" / rgb.filename()).string(), cv::IMREAD_UNCHANGED);
      const double t = std::stod(rgb.stem().string());
      const varslam::TrackedFrame f = slam.track(bgr, depth, t);
      if (!f.pose) continue;
      const auto& p = f.pose->translation;
      const auto& q = f.pose->rotation;  // x y z w
      std::printf("%.6f %.5f %.5f %.5f %.6f %.6f %.6f %.6f\n", t, p[0], p[1], p[2], q[0], q[1], q[2], q[3]);
    }
    slam.finish();
    const varslam::SessionSummary s = slam.summary();
    std::cerr << s.tracked << " of " << s.frames << " frames tracked, " << s.keyframes << " keyframes, person filter: "
              << s.person_detector << "\n";
    return s.tracked > 0 ? 0 : 1;
  } catch (const varslam::InputError& e) {
    std::cerr << "rgbd_folder: " << e.what() << "\n";
    return 2;
  }
}
