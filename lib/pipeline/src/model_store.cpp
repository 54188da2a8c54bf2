#include "model_store.h"

#include "scenewatch/core/files.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <system_error>

namespace scenewatch::pipeline {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {
Eigen::Vector3d vec3(const json& j) { return {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()}; }

OrientedBox box_from(const json& j) {
  OrientedBox b;
  b.center = vec3(j.at("center"));
  const auto& q = j.at("rotation_xyzw");
  b.rotation = Eigen::Quaterniond(q.at(3).get<double>(), q.at(0).get<double>(), q.at(1).get<double>(), q.at(2).get<double>()).normalized();
  b.extents = vec3(j.at("extents"));
  return b;
}

DofFlags flags_from(const json& j) {
  DofFlags f{};
  for (const auto& name : j) {
    bool known = false;
    for (int k = 0; k < kDofCount; ++k) {
      if (name.get<std::string>() == to_string(static_cast<Dof>(k))) f[static_cast<std::size_t>(k)] = known = true;
    }
    if (!known) throw std::invalid_argument("unknown DoF '" + name.get<std::string>() + "'");
  }
  return f;
}

ForegroundState foreground_from(const json& j) {
  ForegroundState s;
  const auto m = j.at("T_world_object").get<std::vector<double>>();
  if (m.size() != 16) throw std::invalid_argument("T_world_object: 16 numbers expected");
  Eigen::Matrix4d M = Eigen::Map<const Eigen::Matrix4d>(m.data());
  if (auto st = validate_rigid(M); !st) throw std::invalid_argument("T_world_object: " + st.error().message);
  s.T_world_object = pose_from_matrix(M);
  s.free = flags_from(j.at("free"));
  for (const auto& jh : j.at("handlings")) {
    Handling h;
    h.start_s = jh.at("start_s").get<double>();
    h.end_s = jh.at("end_s").get<double>();
    const auto r = jh.at("range").get<std::vector<double>>();
    if (r.size() != h.range.size()) throw std::invalid_argument("handling range: 6 numbers expected");
    std::copy(r.begin(), r.end(), h.range.begin());
    h.moved = flags_from(jh.at("moved"));
    s.handlings.push_back(h);
  }
  s.promoted_s = j.at("promoted_s").get<double>();
  s.model_points = j.value("model_points", std::size_t{0});
  s.visible = false;  // until a frame sees it again
  return s;
}

template <typename T, typename F>
Result<T> parse(const char* what, F&& f) {
  try {
    return f();
  } catch (const std::exception& e) {
    return invalid_argument(std::string("malformed ") + what + ": " + e.what());
  }
}
}  // namespace

Result<Plane> plane_from_json(const json& j) {
  return parse<Plane>("plane", [&] {
    Plane p;
    p.id = j.at("id").get<int>();
    p.normal = vec3(j.at("normal"));
    p.d = j.at("d").get<double>();
    for (const auto& h : j.at("hull")) p.hull.push_back(vec3(h));
    p.area_m2 = j.at("area_m2").get<double>();
    p.inlier_count = j.at("inlier_count").get<std::size_t>();
    p.centroid = vec3(j.at("centroid"));
    return p;
  });
}

Result<TrackedObject> object_from_json(const json& j) {
  return parse<TrackedObject>("object", [&] {
    TrackedObject o;
    o.id = j.at("id").get<std::uint64_t>();
    o.cluster.plane_id = j.at("plane_id").get<int>();
    o.cluster.centroid = vec3(j.at("centroid"));
    o.cluster.box = box_from(j.at("box"));
    o.cluster.point_count = j.at("point_count").get<std::size_t>();
    const auto& c = j.at("mean_rgb");
    o.cluster.mean_rgb = Eigen::Vector3f(c.at(0).get<float>(), c.at(1).get<float>(), c.at(2).get<float>());
    if (j.contains("rgb_covariance")) {  // absent in models saved before it existed
      const auto v = j.at("rgb_covariance").get<std::vector<float>>();
      if (v.size() != 9) throw std::runtime_error("rgb_covariance: 9 numbers expected");
      o.cluster.rgb_covariance = Eigen::Map<const Eigen::Matrix3f>(v.data());
      if (!o.cluster.rgb_covariance.allFinite()) throw std::runtime_error("rgb_covariance: not finite");
    }
    o.first_seen_s = j.at("first_seen_s").get<double>();
    o.last_seen_s = j.at("last_seen_s").get<double>();
    o.supported_by = j.value("supported_by", std::uint64_t{0});  // absent in models saved before it existed
    o.observations = j.at("observations").get<int>();
    if (j.contains("foreground")) o.foreground = foreground_from(j.at("foreground"));
    return o;
  });
}


Status write_file_synced(const fs::path& path, const std::string& text) {
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    if (!out) return io_error("'" + path.string() + "': cannot open for writing");
    out << text;
    out.flush();
    if (!out) return io_error("'" + path.string() + "': write failed");
  }
  return fsync_path(path, false);
}

Result<fs::path> current_snapshot(const fs::path& model_dir) {
  std::error_code ec;
  const fs::path link = model_dir / "current";
  if (!fs::is_symlink(link, ec)) return not_found("'" + model_dir.string() + "': no saved model (no 'current' link)");
  const fs::path target = model_dir / fs::read_symlink(link, ec);
  if (ec || !fs::is_directory(target, ec)) {
    return invalid_argument("'" + link.string() + "': points at a missing snapshot folder");
  }
  return target;
}

Status commit_snapshot(const fs::path& model_dir, const std::function<Status(const fs::path&)>& write_files,
                       std::size_t keep) {
  std::error_code ec;
  fs::create_directories(model_dir, ec);
  if (ec) return io_error("'" + model_dir.string() + "': cannot create model directory: " + ec.message());
  // Next snapshot number: one past the highest present.
  int next = 1;
  for (const auto& entry : fs::directory_iterator(model_dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("snap-", 0) == 0) next = std::max(next, std::atoi(name.c_str() + 5) + 1);
  }
  char name[32];
  std::snprintf(name, sizeof(name), "snap-%06d", next);
  const fs::path staging = model_dir / (std::string(name) + ".tmp");
  const fs::path final_dir = model_dir / name;
  fs::remove_all(staging, ec);
  fs::create_directories(staging, ec);
  if (ec) return io_error("'" + staging.string() + "': cannot create: " + ec.message());
  if (auto st = write_files(staging); !st) {
    fs::remove_all(staging, ec);
    return st;
  }
  for (const auto& entry : fs::directory_iterator(staging, ec)) {
    if (auto st = fsync_path(entry.path(), false); !st) return st;
  }
  if (auto st = fsync_path(staging, true); !st) return st;
  fs::rename(staging, final_dir, ec);
  if (ec) return io_error("'" + final_dir.string() + "': cannot rename snapshot into place: " + ec.message());
  const fs::path link_tmp = model_dir / "current.tmp";
  fs::remove(link_tmp, ec);
  fs::create_directory_symlink(name, link_tmp, ec);
  if (ec) return io_error("'" + link_tmp.string() + "': cannot create link: " + ec.message());
  fs::rename(link_tmp, model_dir / "current", ec);  // atomic replacement of the link
  if (ec) return io_error("'" + (model_dir / "current").string() + "': cannot replace link: " + ec.message());
  if (auto st = fsync_path(model_dir, true); !st) return st;
  // Snapshots beyond the newest `keep` are no longer kept.
  const std::vector<fs::path> snapshots = snapshots_newest_first(model_dir);
  for (std::size_t i = std::max<std::size_t>(1, keep); i < snapshots.size(); ++i) {
    if (snapshots[i].filename() != name) fs::remove_all(snapshots[i], ec);
  }
  return {};
}

std::vector<fs::path> snapshots_newest_first(const fs::path& model_dir) {
  std::error_code ec;
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(model_dir, ec)) {
    const std::string n = entry.path().filename().string();
    if (n.rfind("snap-", 0) == 0 && n.find(".tmp") == std::string::npos) names.push_back(n);
  }
  std::sort(names.begin(), names.end(), std::greater<>());  // names sort by number: snap-%06d
  std::vector<fs::path> out;
  for (const auto& n : names) out.push_back(model_dir / n);
  return out;
}

}  // namespace scenewatch::pipeline
