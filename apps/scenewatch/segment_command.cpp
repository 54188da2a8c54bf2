// Offline segmentation of a cloud file: no daemon, the segmentation module directly.
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "config_file.h"
#include "scenewatch/io/cloud_io.h"
#include "scenewatch/segmentation/tabletop.h"
#include "subcommand.h"

namespace scenewatch::cli {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

json vec(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }

json to_json(const Plane& plane, bool with_indices) {
  json hull = json::array();
  for (const auto& p : plane.hull) hull.push_back(vec(p));
  json j = {{"id", plane.id},
            {"normal", vec(plane.normal)},
            {"d", plane.d},
            {"area_m2", plane.area_m2},
            {"inlier_count", plane.inlier_count},
            {"centroid", vec(plane.centroid)},
            {"hull", std::move(hull)}};
  if (with_indices) j["indices"] = plane.indices;
  return j;
}

json to_json(std::size_t id, const ObjectCluster& object) {
  const Eigen::Quaterniond& q = object.box.rotation;
  return {{"id", id},
          {"plane_id", object.plane_id},
          {"supported_by", object.supported_by},
          {"centroid", vec(object.centroid)},
          {"box",
           {{"center", vec(object.box.center)},
            {"rotation", {{"w", q.w()}, {"x", q.x()}, {"y", q.y()}, {"z", q.z()}}},
            {"extents", vec(object.box.extents)}}},
          {"point_count", object.point_count},
          {"mean_rgb", json::array({object.mean_rgb.x(), object.mean_rgb.y(), object.mean_rgb.z()})},
          {"indices", object.indices}};
}

std::string fixed(double value, int decimals = 3) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  return buffer;
}

std::string text(const Eigen::Vector3d& v) {
  return "(" + fixed(v.x()) + ", " + fixed(v.y()) + ", " + fixed(v.z()) + ")";
}

Cloud subset(const Cloud& cloud, const std::vector<int>& indices) {
  Cloud out;
  out.points.reserve(indices.size());
  for (const int i : indices) {
    if (i >= 0 && static_cast<std::size_t>(i) < cloud.points.size()) out.points.push_back(cloud.points[static_cast<std::size_t>(i)]);
  }
  out.width = static_cast<std::uint32_t>(out.points.size());
  out.height = 1;
  out.is_dense = false;
  return out;
}

std::string numbered(const char* stem, std::size_t i) {
  char name[64];
  std::snprintf(name, sizeof name, "%s_%03zu.pcd", stem, i);
  return name;
}

}  // namespace

int run_segment(const SegmentOptions& options) {
  auto loaded = read_config_file(options.config);
  if (!loaded) return fail(loaded.error().message);
  const segmentation::Config& config = loaded->segmentation;
  auto file = io::read_cloud(options.file);
  if (!file) {
    const std::string& message = file.error().message;
    return fail(message.find(options.file) != std::string::npos ? message : options.file + ": " + message);
  }
  const Cloud& cloud = *file->cloud;
  const segmentation::Segmentation result = segmentation::segment(cloud, config, file->sensor_origin);

  std::vector<std::string> written;
  if (!options.out_dir.empty()) {
    std::error_code ec;
    fs::create_directories(options.out_dir, ec);
    if (ec) return fail("cannot create " + options.out_dir + ": " + ec.message());
    for (std::size_t i = 0; i < result.objects.size(); ++i) {
      const fs::path path = fs::path(options.out_dir) / numbered("object", i);
      if (Status s = io::write_pcd(path, subset(cloud, result.objects[i].indices)); !s) return fail(s.error().message);
      written.push_back(path.string());
    }
    for (std::size_t i = 0; i < result.planes.size(); ++i) {
      const fs::path path = fs::path(options.out_dir) / numbered("plane", i);
      if (Status s = io::write_pcd(path, subset(cloud, result.planes[i].indices)); !s) return fail(s.error().message);
      written.push_back(path.string());
    }
  }

  if (options.json) {
    json planes = json::array(), objects = json::array();
    for (const auto& plane : result.planes) planes.push_back(to_json(plane, options.plane_indices));
    for (std::size_t i = 0; i < result.objects.size(); ++i) objects.push_back(to_json(i, result.objects[i]));
    json j = {{"file", options.file},
              {"width", cloud.width},
              {"height", cloud.height},
              {"points", cloud.points.size()},
              {"valid_points", file->valid_points},
              {"sensor_origin", vec(file->sensor_origin)},
              {"planes", std::move(planes)},
              {"objects", std::move(objects)},
              {"written", written}};
    std::cout << j.dump() << std::endl;
    return kExitOk;
  }
  std::cout << options.file << ": " << cloud.points.size() << " points (" << file->valid_points << " valid)\n";
  std::cout << result.planes.size() << (result.planes.size() == 1 ? " plane\n" : " planes\n");
  for (const auto& p : result.planes) {
    std::cout << "  plane " << p.id << ": normal " << text(p.normal) << ", d " << fixed(p.d) << ", area "
              << fixed(p.area_m2, 2) << " m2, " << p.inlier_count << " inliers\n";
  }
  std::cout << result.objects.size() << (result.objects.size() == 1 ? " object\n" : " objects\n");
  for (std::size_t i = 0; i < result.objects.size(); ++i) {
    const auto& o = result.objects[i];
    const std::string on = o.supported_by >= 0 ? "on object " + std::to_string(o.supported_by) : "on plane " + std::to_string(o.plane_id);
    std::cout << "  object " << i << " " << on << ": at " << text(o.centroid) << ", size "
              << fixed(o.box.extents.x()) << " x " << fixed(o.box.extents.y()) << " x " << fixed(o.box.extents.z())
              << " m, " << o.point_count << " points\n";
  }
  if (!written.empty()) std::cout << "wrote " << written.size() << " files to " << options.out_dir << "\n";
  std::cout << std::flush;
  return kExitOk;
}

void add_segment_command(CLI::App& app, Action& action) {
  auto options = std::make_shared<SegmentOptions>();
  auto* segment = app.add_subcommand(
      "segment", "offline: find supporting planes and the objects on them in a cloud file (no daemon)");
  segment->add_option("file", options->file, "cloud file (.pcd or .ply)")->required();
  segment->add_flag("--json", options->json, "print JSON (objects with the indices of their points)");
  segment->add_option("--out", options->out_dir,
                      "write object_000.pcd, ... and plane_000.pcd, ... into this folder");
  segment->add_option("--config", options->config, "YAML config (its segmentation section is used)");
  segment->add_flag("--plane-indices", options->plane_indices, "with --json: also list plane inlier indices");
  on_parsed(segment, action, [options] { return run_segment(*options); });
}

}  // namespace scenewatch::cli
