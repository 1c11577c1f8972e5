#include "viewer/viewer_assets.hpp"

#include <fmt/format.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "core/error.hpp"

namespace varslam::viewer {
namespace fs = std::filesystem;
namespace {

struct AssetFile {
  const char* url;
  const char* file;  // relative to the asset folder
  const char* content_type;
};

// Scripts go as application/x-javascript, one of the JavaScript types browsers accept for modules, because httplib
// brotli-compresses every text/* body at its slowest setting (2.5 s for three.js, on each page load) and cannot be
// told not to; on loopback compression gains nothing.
constexpr const char* kScript = "application/x-javascript; charset=utf-8";

constexpr AssetFile kAssets[] = {
    {"/", "index.html", "text/html; charset=utf-8"},
    {"/viewer.css", "viewer.css", "text/css; charset=utf-8"},
    {"/viewer.js", "viewer.js", kScript},
    {"/three/three.module.js", "three/three.module.js", kScript},
    {"/three/three.core.js", "three/three.core.js", kScript},
    {"/three/OrbitControls.js", "three/OrbitControls.js", kScript},
};

std::optional<fs::path> running_binary_dir() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return std::nullopt;
  return exe.parent_path();
}

bool complete(const fs::path& dir) {
  for (const AssetFile& a : kAssets)
    if (!fs::is_regular_file(dir / a.file)) return false;
  return true;
}

}  // namespace

std::vector<fs::path> asset_search_path(const std::optional<fs::path>& dir) {
  std::vector<fs::path> path;
  if (dir) path.push_back(*dir);
  if (const char* env = std::getenv("VARSLAM_VIEWER_DIR"); env && *env) path.emplace_back(env);
  if (const auto bin = running_binary_dir()) {
    path.push_back(*bin / ".." / "share" / "varslam" / "viewer");
    path.push_back(*bin / "share" / "varslam" / "viewer");
  }
  return path;
}

std::vector<Asset> load_assets(const std::optional<fs::path>& dir) { return load_assets_from(asset_search_path(dir)); }

std::vector<Asset> load_assets_from(const std::vector<fs::path>& search) {
  const fs::path* found = nullptr;
  for (const fs::path& d : search)
    if (complete(d)) {
      found = &d;
      break;
    }
  if (!found) {
    std::string where;
    for (const fs::path& d : search) where += (where.empty() ? "" : ", ") + d.lexically_normal().string();
    throw InputError(
        fmt::format("the viewer's page and scripts (index.html, viewer.js, three/three.module.js, ...) "
                    "are not in {}; build with the viewer (npm installs three.js) or set "
                    "VARSLAM_VIEWER_DIR",
                    where.empty() ? "any folder searched" : where));
  }
  std::vector<Asset> assets;
  for (const AssetFile& a : kAssets) {
    const fs::path file = *found / a.file;
    std::ifstream in(file, std::ios::binary);
    std::ostringstream body;
    body << in.rdbuf();
    if (!in.good() && !in.eof()) throw InputError(fmt::format("{}: cannot be read", file.string()));
    assets.push_back({a.url, a.content_type, body.str()});
  }
  return assets;
}

}  // namespace varslam::viewer
