#include "io/boxes_io.hpp"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "io/text_lines.hpp"

namespace varslam {

BoxesByTime read_boxes_file(const std::filesystem::path& file) {
  BoxesByTime out;
  for_each_data_line(file, "boxes file", [&](const TextLine& l) {
    Detection d;
    double v[6] = {};  // timestamp score x y w h
    bool ok = l.tokens.size() == 7;
    if (ok) d.label = l.tokens[1];
    const int token_of[6] = {0, 2, 3, 4, 5, 6};
    for (int k = 0; ok && k < 6; ++k) ok = parse_double(l.tokens[token_of[k]], v[k]);
    if (!ok)
      throw InputError(fmt::format("{}: expected 'timestamp label score x y w h', got '{}'", l.where, *l.text));
    for (double x : v)
      if (!std::isfinite(x)) throw InputError(fmt::format("{}: non-finite value in '{}'", l.where, *l.text));
    if (v[4] < 0 || v[5] < 0) throw InputError(fmt::format("{}: negative box size in '{}'", l.where, *l.text));
    // Pixels and scores as floats: beyond this a value is garbage, and converting it would be undefined.
    constexpr double kMaxValue = 1e7;
    for (int k = 1; k < 6; ++k)
      if (std::abs(v[k]) > kMaxValue)
        throw InputError(fmt::format("{}: value {} out of range (at most {:g} in magnitude) in '{}'", l.where, v[k],
                                     kMaxValue, *l.text));
    d.timestamp = v[0];
    d.score = static_cast<float>(v[1]);
    d.box = cv::Rect2f(static_cast<float>(v[2]), static_cast<float>(v[3]), static_cast<float>(v[4]),
                       static_cast<float>(v[5]));
    out[d.timestamp].push_back(std::move(d));
  });
  return out;
}

void write_boxes_file(const BoxesByTime& boxes, const std::filesystem::path& file) {
  std::string text = "# timestamp label score x y w h (pixels)\n";
  for (const auto& [t, dets] : boxes)
    for (const auto& d : dets)
      text += fmt::format("{:.6f} {} {:.3f} {:.1f} {:.1f} {:.1f} {:.1f}\n", t, d.label, d.score, d.box.x, d.box.y,
                          d.box.width, d.box.height);
  write_file_atomically(file, text, "boxes file");
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
