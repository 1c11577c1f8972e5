// YOLO (Darknet cfg+weights or ONNX) person detector through cv::dnn on the CPU.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <fstream>
#include <opencv2/dnn.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.hpp"
#include "semantic/detector_impl.hpp"

namespace varslam::semantic {
namespace {

std::vector<std::string> read_names(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(fmt::format("{}: cannot open class names file", file.string()));
  std::vector<std::string> names;
  std::string line;
  while (std::getline(in, line)) {
    const auto b = line.find_first_not_of(" \t\r");
    const auto e = line.find_last_not_of(" \t\r");
    names.push_back(b == std::string::npos ? std::string{} : line.substr(b, e - b + 1));
  }
  while (!names.empty() && names.back().empty()) names.pop_back();
  if (names.empty()) throw InputError(fmt::format("{}: class names file is empty", file.string()));
  return names;
}

class YoloDetector final : public Detector {
 public:
  YoloDetector(const DetectorConfig& cfg, const YoloFiles& files) : cfg_(cfg), onnx_(files.cfg.empty()) {
    const auto names = read_names(files.names);
    for (int i = 0; i < static_cast<int>(names.size()); ++i) {
      std::string label = kept_label(cfg, names[static_cast<std::size_t>(i)]);
      if (!label.empty()) kept_.push_back({i, std::move(label)});
    }
    if (kept_.empty())
      throw InputError(fmt::format("{}: none of the detector classes ({}) is in this class list (aliases "
                                   "applied); check semantic.classes or names_file",
                                   files.names.string(), fmt::join(cfg.classes, ", ")));
    if (cfg.input_size <= 0 || cfg.input_size % 32 != 0)
      throw ConfigError(fmt::format("yolo detector: input_size {} must be a positive multiple of 32",
                                    cfg.input_size));
    try {
      net_ = onnx_ ? cv::dnn::readNetFromONNX(files.weights.string())
                   : cv::dnn::readNetFromDarknet(files.cfg.string(), files.weights.string());
    } catch (const cv::Exception& e) {
      throw InputError(fmt::format("{}: cannot load the network ({})",
                                   (onnx_ ? files.weights : files.cfg).string(), e.what()));
    }
    if (net_.empty()) throw InputError(fmt::format("{}: cannot load the network", files.weights.string()));
    net_.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
    net_.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
    if (cfg.num_threads > 0) cv::setNumThreads(cfg.num_threads);
    out_names_ = net_.getUnconnectedOutLayersNames();
    name_ = fmt::format("yolo({}, {})", files.weights.filename().string(), cfg.input_size);
  }

  Detections detect(const cv::Mat& bgr, double timestamp) override {
    if (bgr.empty()) return {};
    cv::Mat image = bgr;
    if (bgr.channels() == 1) cv::cvtColor(bgr, image, cv::COLOR_GRAY2BGR);
    // Stretch to the square input (no letterbox): relative outputs map straight back to the image size.
    const cv::Size in(cfg_.input_size, cfg_.input_size);
    cv::dnn::blobFromImage(image, blob_, 1.0 / 255.0, in, cv::Scalar(), /*swapRB=*/true, /*crop=*/false);
    net_.setInput(blob_);
    net_.forward(outs_, out_names_);

    std::vector<cv::Rect> rects;
    std::vector<float> scores;
    std::vector<int> kept_index;  // into kept_
    const float w = static_cast<float>(image.cols), h = static_cast<float>(image.rows);
    for (cv::Mat out : outs_) {
      if (out.dims > 2) out = out.reshape(1, static_cast<int>(out.total() / out.size[out.dims - 1]));
      if (out.cols < 6 || out.type() != CV_32F) continue;
      const int n_classes = out.cols - 5;
      for (int r = 0; r < out.rows; ++r) {
        const float* row = out.ptr<float>(r);
        const float objectness = row[4];
        if (objectness < cfg_.conf_threshold) continue;  // score <= objectness, so nothing below can pass
        float best = 0.0f;
        int best_k = -1;
        for (int k = 0; k < static_cast<int>(kept_.size()); ++k) {
          const int c = kept_[static_cast<std::size_t>(k)].class_id;
          if (c >= n_classes) continue;
          // OpenCV's Darknet region layer already multiplies class scores by objectness; ONNX exports do not.
          const float s = onnx_ ? objectness * row[5 + c] : row[5 + c];
          if (s > best) best = s, best_k = k;
        }
        if (best_k < 0 || best < cfg_.conf_threshold) continue;
        float cx = row[0], cy = row[1], bw = row[2], bh = row[3];
        if (onnx_ && (cx > 2.0f || cy > 2.0f || bw > 2.0f || bh > 2.0f)) {  // pixel coords of the input square
          const float s = 1.0f / static_cast<float>(cfg_.input_size);
          cx *= s, cy *= s, bw *= s, bh *= s;
        }
        const float x0 = std::max(0.0f, (cx - bw / 2) * w), y0 = std::max(0.0f, (cy - bh / 2) * h);
        const float x1 = std::min(w, (cx + bw / 2) * w), y1 = std::min(h, (cy + bh / 2) * h);
        if (x1 <= x0 || y1 <= y0) continue;
        rects.emplace_back(cv::Point(cvRound(x0), cvRound(y0)), cv::Point(cvRound(x1), cvRound(y1)));
        scores.push_back(best);
        kept_index.push_back(best_k);
      }
    }
    Detections dets;
    // NMS per kept label so a person box never suppresses, say, a bicycle box.
    for (std::size_t k = 0; k < kept_.size(); ++k) {
      std::vector<cv::Rect> kr;
      std::vector<float> ks;
      for (std::size_t i = 0; i < rects.size(); ++i)
        if (kept_index[i] == static_cast<int>(k)) kr.push_back(rects[i]), ks.push_back(scores[i]);
      if (kr.empty()) continue;
      std::vector<int> keep;
      cv::dnn::NMSBoxes(kr, ks, cfg_.conf_threshold, cfg_.nms_threshold, keep);
      for (int i : keep) {
        Detection d;
        d.timestamp = timestamp;
        d.label = kept_[k].label;
        d.score = ks[static_cast<std::size_t>(i)];
        d.box = cv::Rect2f(kr[static_cast<std::size_t>(i)]);
        dets.push_back(std::move(d));
      }
    }
    return dets;
  }

  std::string name() const override { return name_; }

 private:
  struct KeptClass {
    int class_id;
    std::string label;  // after aliasing
  };
  DetectorConfig cfg_;
  bool onnx_;
  cv::dnn::Net net_;
  std::vector<KeptClass> kept_;
  std::vector<std::string> out_names_;
  std::string name_;
  cv::Mat blob_;
  std::vector<cv::Mat> outs_;
};

}  // namespace

std::unique_ptr<Detector> make_yolo_detector(const DetectorConfig& cfg, const YoloFiles& files) {
  return std::make_unique<YoloDetector>(cfg, files);
}

}  // namespace varslam::semantic
