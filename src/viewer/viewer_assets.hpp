#pragma once
// The viewer's page and scripts (viewer/ in the source tree; three.js from the npm registry, installed by the build).
// Read into memory once: the server answers from this fixed list only, so no path from a request reaches the file
// system.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace varslam::viewer {

struct Asset {
  std::string url;           // what the browser asks for, e.g. "/three/three.module.js"
  std::string content_type;  // e.g. "text/javascript"
  std::string body;
};

/// Where the assets are looked for, in order: `dir` when given, $VARSLAM_VIEWER_DIR, then share/varslam/viewer next to
/// the running binary (<bin>/../share/..., the install and build layouts, and <bin>/share/..., the tests').
std::vector<std::filesystem::path> asset_search_path(const std::optional<std::filesystem::path>& dir = std::nullopt);

/// Reads every asset from the first of `folders` that has them all. Throws InputError naming the folders searched.
std::vector<Asset> load_assets_from(const std::vector<std::filesystem::path>& folders);
/// load_assets_from(asset_search_path(dir)).
std::vector<Asset> load_assets(const std::optional<std::filesystem::path>& dir = std::nullopt);

}  // namespace varslam::viewer
