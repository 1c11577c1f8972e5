// varslam_mesh_render: draws a dense mesh (the binary PLY `varslam run --dense-map` writes) into a PNG without a
// display: a z-buffered software rasteriser, each triangle in its vertices' colour shaded by its angle to the view.
//   varslam_mesh_render --mesh out/dense_mesh.ply --png mesh.png [--eye x,y,z --target x,y,z] [--shade-only]
#include <CLI/CLI.hpp>
#include <Eigen/Geometry>
#include <array>
#include <cstdio>
#include <fstream>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

namespace {

struct Mesh {
  std::vector<Eigen::Vector3f> v;
  std::vector<std::array<std::uint8_t, 3>> rgb;
  std::vector<std::array<int, 3>> f;
};

Mesh read_ply(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::string line;
  std::size_t nv = 0, nf = 0;
  bool binary = false;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string a, b;
    s >> a >> b;
    if (a == "format") binary = b == "binary_little_endian";
    if (a == "element" && b == "vertex") s >> nv;
    if (a == "element" && b == "face") s >> nf;
    if (a == "end_header") break;
  }
  if (!binary) throw std::runtime_error(path + ": not a binary little-endian PLY of varslam's dense mesh");
  Mesh m;
  m.v.resize(nv);
  m.rgb.resize(nv);
  m.f.resize(nf);
  for (std::size_t i = 0; i < nv; ++i) {
    in.read(reinterpret_cast<char*>(m.v[i].data()), 12);
    in.read(reinterpret_cast<char*>(m.rgb[i].data()), 3);
  }
  for (std::size_t i = 0; i < nf; ++i) {
    std::uint8_t n = 0;
    in.read(reinterpret_cast<char*>(&n), 1);
    if (n != 3) throw std::runtime_error(path + ": only triangles are supported");
    in.read(reinterpret_cast<char*>(m.f[i].data()), 12);
  }
  if (!in) throw std::runtime_error(path + ": truncated");
  return m;
}

Eigen::Vector3f parse3(const std::string& s) {
  Eigen::Vector3f p;
  if (std::sscanf(s.c_str(), "%f,%f,%f", &p.x(), &p.y(), &p.z()) != 3) throw std::runtime_error("expected x,y,z: " + s);
  return p;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Render a dense mesh (binary PLY) to a PNG, headless"};
  std::string mesh_path, png, eye_s, target_s;
  int width = 1280, height = 960;
  double fov_deg = 70;
  bool shade_only = false;
  app.add_option("--mesh", mesh_path, "dense_mesh.ply")->required();
  app.add_option("--png", png, "Output image")->required();
  app.add_option("--eye", eye_s, "Viewpoint x,y,z (world frame, y down); default: behind and above the first camera");
  app.add_option("--target", target_s, "Point looked at x,y,z; default: the mesh's centroid");
  app.add_option("--width", width)->capture_default_str();
  app.add_option("--height", height)->capture_default_str();
  app.add_option("--fov", fov_deg, "Horizontal field of view (degrees)")->capture_default_str();
  app.add_flag("--shade-only", shade_only, "Grey surfaces, shaded by their angle (shape without texture)");
  CLI11_PARSE(app, argc, argv);
  try {
    const Mesh m = read_ply(mesh_path);
    if (m.v.empty()) throw std::runtime_error(mesh_path + ": no vertices");
    Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
    for (const auto& p : m.v) centroid += p;
    centroid /= static_cast<float>(m.v.size());
    const Eigen::Vector3f target = target_s.empty() ? centroid : parse3(target_s);
    const Eigen::Vector3f eye = eye_s.empty() ? Eigen::Vector3f(0.0f, -1.2f, -1.8f) : parse3(eye_s);
    // Camera looking from eye to target, y down (the SLAM world frame's convention).
    const Eigen::Vector3f z = (target - eye).normalized();
    Eigen::Vector3f x = Eigen::Vector3f(0, 1, 0).cross(z);
    if (x.norm() < 1e-6f) x = Eigen::Vector3f(1, 0, 0);
    x.normalize();
    const Eigen::Vector3f y = z.cross(x);
    const float f = static_cast<float>(width / 2.0 / std::tan(fov_deg * M_PI / 360.0));
    const float cx = static_cast<float>(width) / 2, cy = static_cast<float>(height) / 2;
    std::vector<Eigen::Vector3f> pc(m.v.size());
    for (std::size_t i = 0; i < m.v.size(); ++i) {
      const Eigen::Vector3f d = m.v[i] - eye;
      pc[i] = {d.dot(x), d.dot(y), d.dot(z)};
    }
    cv::Mat img(height, width, CV_8UC3, cv::Scalar(60, 50, 45));
    std::vector<float> zbuf(static_cast<std::size_t>(width) * static_cast<std::size_t>(height),
                            std::numeric_limits<float>::infinity());
    for (const auto& t : m.f) {
      const Eigen::Vector3f &a = pc[t[0]], &b = pc[t[1]], &c = pc[t[2]];
      if (a.z() < 0.05f || b.z() < 0.05f || c.z() < 0.05f) continue;
      const Eigen::Vector2f pa(f * a.x() / a.z() + cx, f * a.y() / a.z() + cy), pb(f * b.x() / b.z() + cx, f * b.y() / b.z() + cy),
          pcc(f * c.x() / c.z() + cx, f * c.y() / c.z() + cy);
      const float area = (pb - pa).x() * (pcc - pa).y() - (pb - pa).y() * (pcc - pa).x();
      if (std::abs(area) < 1e-9f) continue;
      const Eigen::Vector3f n = (b - a).cross(c - a).normalized();
      const float shade = 0.25f + 0.75f * std::abs(n.dot((a + b + c).normalized()));
      const int x0 = std::max(0, static_cast<int>(std::floor(std::min({pa.x(), pb.x(), pcc.x()})))),
                x1 = std::min(width - 1, static_cast<int>(std::ceil(std::max({pa.x(), pb.x(), pcc.x()})))),
                y0 = std::max(0, static_cast<int>(std::floor(std::min({pa.y(), pb.y(), pcc.y()})))),
                y1 = std::min(height - 1, static_cast<int>(std::ceil(std::max({pa.y(), pb.y(), pcc.y()}))));
      for (int py = y0; py <= y1; ++py)
        for (int px = x0; px <= x1; ++px) {
          const Eigen::Vector2f p(static_cast<float>(px) + 0.5f, static_cast<float>(py) + 0.5f);
          const float w0 = ((pb - p).x() * (pcc - p).y() - (pb - p).y() * (pcc - p).x()) / area;
          const float w1 = ((pcc - p).x() * (pa - p).y() - (pcc - p).y() * (pa - p).x()) / area;
          const float w2 = 1 - w0 - w1;
          if (w0 < 0 || w1 < 0 || w2 < 0) continue;
          const float depth = w0 * a.z() + w1 * b.z() + w2 * c.z();
          float& zb = zbuf[static_cast<std::size_t>(py) * static_cast<std::size_t>(width) + static_cast<std::size_t>(px)];
          if (depth >= zb) continue;
          zb = depth;
          cv::Vec3b& out = img.at<cv::Vec3b>(py, px);
          for (int ch = 0; ch < 3; ++ch) {
            const float col = shade_only ? 200.0f
                                         : w0 * m.rgb[t[0]][ch] + w1 * m.rgb[t[1]][ch] + w2 * m.rgb[t[2]][ch];
            out[2 - ch] = static_cast<std::uint8_t>(std::clamp(col * shade, 0.0f, 255.0f));
          }
        }
    }
    if (!cv::imwrite(png, img)) throw std::runtime_error(png + ": cannot write");
    std::printf("%s: %zu vertices, %zu triangles -> %s\n", mesh_path.c_str(), m.v.size(), m.f.size(), png.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
  return 0;
}
