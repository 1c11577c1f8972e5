#include "io/boxes_io.hpp"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "core/error.hpp"

namespace varslam {

BoxesByTime read_boxes_file(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(fmt::format("{}: cannot open boxes file", file.string()));
  BoxesByTime out;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream ss(line);
    Detection d;
    float x = 0, y = 0, w = 0, h = 0;
    if (!(ss >> d.timestamp >> d.label >> d.score >> x >> y >> w >> h))
      throw InputError(fmt::format("{}:{}: expected 'timestamp label score x y w h', got '{}'", file.string(),
                                   line_no, line));
    if (!std::isfinite(d.timestamp) || !std::isfinite(x) || !std::isfinite(y) || w < 0 || h < 0 ||
        !std::isfinite(w) || !std::isfinite(h))
      throw InputError(fmt::format("{}:{}: non-finite value or negative box size", file.string(), line_no));
    d.box = cv::Rect2f(x, y, w, h);
    out[d.timestamp].push_back(std::move(d));
  }
  return out;
}

void write_boxes_file(const BoxesByTime& boxes, const std::filesystem::path& file) {
  std::ofstream out(file);
  if (!out) throw InputError(fmt::format("{}: cannot write boxes file", file.string()));
  out << "# timestamp label score x y w h (pixels)\n";
  for (const auto& [t, dets] : boxes)
    for (const auto& d : dets)
      out << fmt::format("{:.6f} {} {:.3f} {:.1f} {:.1f} {:.1f} {:.1f}\n", t, d.label, d.score, d.box.x, d.box.y,
                         d.box.width, d.box.height);
}

Detections boxes_near(const BoxesByTime& boxes, double t, double max_dt) {
  if (boxes.empty()) return {};
  auto it = boxes.lower_bound(t);
  const Detections* best = nullptr;
  double best_dt = max_dt;
  if (it != boxes.end() && std::abs(it->first - t) <= best_dt) {
    best = &it->second;
    best_dt = std::abs(it->first - t);
  }
  if (it != boxes.begin()) {
    --it;
    if (std::abs(it->first - t) <= best_dt) best = &it->second;
  }
  return best ? *best : Detections{};
}

}  // namespace varslam
