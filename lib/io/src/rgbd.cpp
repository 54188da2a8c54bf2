// RGB-D back-projection and the small text formats: intrinsics, 4x4 poses, TUM trajectories.
#include <algorithm>
#include <cmath>
#include <functional>
#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>

#include "scenewatch/core/files.h"
#include "scenewatch/io/rgbd.h"

namespace scenewatch::io {
namespace fs = std::filesystem;

namespace {

// Calls f(line_no, line) for every line of a text file with '#' comments cut off; stops at the
// first error f returns.
Status for_each_line(const fs::path& path, const std::function<Status(int, const std::string&)>& f) {
  if (auto st = check_readable_file(path); !st) return st;
  std::ifstream in(path);
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    if (auto st = f(line_no, line); !st) return st;
  }
  return {};
}

// Reads every whitespace-separated number of a small text file.
Result<std::vector<double>> read_numbers(const fs::path& path) {
  std::vector<double> values;
  auto st = for_each_line(path, [&](int line_no, const std::string& line) -> Status {
    std::istringstream ls(line);
    std::string token;
    while (ls >> token) {
      char* end = nullptr;
      const double v = std::strtod(token.c_str(), &end);
      if (end == token.c_str() || *end != '\0') {
        return invalid_argument(quoted(path) + " line " + std::to_string(line_no) + ": '" + token + "' is not a number");
      }
      // "inf", "nan" and overflowing numbers (5e502) parse, but no camera matrix or pose holds them
      // (found by fuzz_poses: an infinite focal length was accepted).
      if (!std::isfinite(v)) {
        return invalid_argument(quoted(path) + " line " + std::to_string(line_no) + ": '" + token +
                                "' is non-finite (no camera matrix or pose holds one)");
      }
      values.push_back(v);
    }
    return {};
  });
  if (!st) return st.error();
  return values;
}

Status write_text(const fs::path& path, const std::string& text) {
  std::error_code ec;
  if (path.has_parent_path()) fs::create_directories(path.parent_path(), ec);
  return with_system_reason([&]() -> Status {
    std::ofstream out(path);
    if (!out) return io_error(quoted(path) + ": cannot open for writing");
    out << text;
    out.close();  // the bytes reach the file here: a full disk fails now, not silently in the destructor
    if (!out) return io_error(quoted(path) + ": write failed");
    return {};
  });
}

}  // namespace

Status validate_depth_scale(double depth_scale_m, const std::string& where) {
  if (!(std::isfinite(depth_scale_m) && depth_scale_m > 0 && depth_scale_m <= 1.0)) {
    std::ostringstream os;
    os << where << ": the depth scale must be in (0, 1] metres per depth unit (0.001 for millimetres), got "
       << depth_scale_m;
    return invalid_argument(os.str());
  }
  return {};
}

Result<double> read_depth_scale(const fs::path& path) {
  auto values = read_numbers(path);
  if (!values) return values.error();
  if (values->size() != 1) {
    return invalid_argument(quoted(path) + ": expected one number, the metres per depth unit, found " +
                            std::to_string(values->size()));
  }
  if (auto st = validate_depth_scale(values->front(), quoted(path)); !st) return st.error();
  return values->front();
}

Result<CloudPtr> rgbd_to_cloud(const ColorImage& color, const DepthImage& depth, const Intrinsics& K, double depth_scale_m,
                               double max_depth_m) {
  if (auto st = validate_depth_scale(depth_scale_m, "rgbd_to_cloud"); !st) return st.error();
  if (depth.empty()) return invalid_argument("depth image is empty");
  if (depth.depth_mm.size() != static_cast<std::size_t>(depth.width) * depth.height) {
    return invalid_argument("depth buffer size does not match its width x height");
  }
  if (color.width != depth.width || color.height != depth.height) {
    return invalid_argument("colour (" + std::to_string(color.width) + "x" + std::to_string(color.height) +
                            ") and depth (" + std::to_string(depth.width) + "x" + std::to_string(depth.height) +
                            ") sizes differ");
  }
  if (color.rgb.size() != static_cast<std::size_t>(color.width) * color.height * 3) {
    return invalid_argument("colour buffer size does not match its width x height");
  }
  if (!(K.fx > 0 && K.fy > 0) || !std::isfinite(K.cx) || !std::isfinite(K.cy)) {
    return invalid_argument("intrinsics are invalid (fx, fy must be > 0)");
  }
  if ((K.width != 0 && K.width != depth.width) || (K.height != 0 && K.height != depth.height)) {
    return invalid_argument("intrinsics are for " + std::to_string(K.width) + "x" + std::to_string(K.height) +
                            " images, depth is " + std::to_string(depth.width) + "x" + std::to_string(depth.height));
  }
  auto cloud = std::make_shared<Cloud>(depth.width, depth.height);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const double inv_fx = 1.0 / K.fx, inv_fy = 1.0 / K.fy;
  std::size_t valid = 0;
  for (int v = 0; v < depth.height; ++v) {
    for (int u = 0; u < depth.width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * depth.width + u;
      PointT& p = cloud->points[i];
      p.r = color.rgb[3 * i];
      p.g = color.rgb[3 * i + 1];
      p.b = color.rgb[3 * i + 2];
      const std::uint16_t d = depth.depth_mm[i];
      const double z = d * depth_scale_m;
      // 0 is "no depth" everywhere; 65535 is 7-Scenes' marker for it.
      if (d == 0 || d == 65535 || z > max_depth_m) {
        p.x = p.y = p.z = nan;
        continue;
      }
      p.x = static_cast<float>((u - K.cx) * z * inv_fx);
      p.y = static_cast<float>((v - K.cy) * z * inv_fy);
      p.z = static_cast<float>(z);
      ++valid;
    }
  }
  if (valid == 0) return invalid_argument("depth image has no valid pixel");
  cloud->is_dense = false;
  return cloud;
}

Result<Intrinsics> read_intrinsics(const fs::path& path) {
  auto values = read_numbers(path);
  if (!values) return values.error();
  if (values->size() != 9) {
    return invalid_argument(quoted(path) + ": expected a 3x3 camera matrix (9 numbers), found " +
                            std::to_string(values->size()));
  }
  const auto& k = *values;
  if (k[1] != 0 || k[3] != 0 || k[6] != 0 || k[7] != 0 || k[8] != 1) {
    return invalid_argument(quoted(path) + ": not a pinhole camera matrix [fx 0 cx; 0 fy cy; 0 0 1]");
  }
  Intrinsics K;
  K.fx = k[0];
  K.cx = k[2];
  K.fy = k[4];
  K.cy = k[5];
  if (!(K.fx > 0 && K.fy > 0)) return invalid_argument(quoted(path) + ": focal lengths must be > 0");
  return K;
}

Status write_intrinsics(const fs::path& path, const Intrinsics& K) {
  std::ostringstream os;
  os << std::setprecision(10) << K.fx << " 0 " << K.cx << "\n0 " << K.fy << " " << K.cy << "\n0 0 1\n";
  return write_text(path, os.str());
}

Result<Pose> read_pose_matrix(const fs::path& path) {
  auto values = read_numbers(path);
  if (!values) return values.error();
  if (values->size() != 16) {
    return invalid_argument(quoted(path) + ": expected a 4x4 matrix (16 numbers), found " + std::to_string(values->size()));
  }
  Eigen::Matrix4d m;
  for (int i = 0; i < 16; ++i) m(i / 4, i % 4) = (*values)[i];
  if (auto st = validate_rigid(m); !st) return invalid_argument(quoted(path) + ": " + st.error().message);
  return pose_from_matrix(m);
}

Status write_pose_matrix(const fs::path& path, const Pose& T_world_camera) {
  std::ostringstream os;
  os << std::setprecision(12);
  const Eigen::Matrix4d m = T_world_camera.matrix();
  for (int r = 0; r < 4; ++r) os << m(r, 0) << " " << m(r, 1) << " " << m(r, 2) << " " << m(r, 3) << "\n";
  return write_text(path, os.str());
}

Result<std::vector<StampedPose>> read_tum(const fs::path& path) {
  std::vector<StampedPose> poses;
  auto st = for_each_line(path, [&](int line_no, const std::string& line) -> Status {
    if (line.find_first_not_of(" \t\r") == std::string::npos) return {};
    std::istringstream ls(line);
    double v[8];
    int n = 0;
    while (n < 8 && ls >> v[n]) ++n;
    std::string rest;
    const std::string where = quoted(path) + " line " + std::to_string(line_no) + ": ";
    if (n != 8 || (ls.clear(), ls >> rest)) return invalid_argument(where + "expected 't tx ty tz qx qy qz qw'");
    for (double x : v) {
      if (!std::isfinite(x)) return invalid_argument(where + "non-finite value");
    }
    Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    if (std::abs(q.norm() - 1.0) > 1e-2) {
      return invalid_argument(where + "quaternion is not unit length (norm " + std::to_string(q.norm()) + ")");
    }
    StampedPose sp;
    sp.stamp_s = v[0];
    sp.T_world_camera = Pose::Identity();
    sp.T_world_camera.linear() = q.normalized().toRotationMatrix();
    sp.T_world_camera.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
    poses.push_back(sp);
    return {};
  });
  if (!st) return st.error();
  if (poses.empty()) return invalid_argument(quoted(path) + ": no poses");
  return poses;
}

Status write_tum(const fs::path& path, const std::vector<StampedPose>& poses) {
  std::ostringstream os;
  os << "# timestamp tx ty tz qx qy qz qw (T_world_camera)\n" << std::setprecision(12);
  for (const auto& p : poses) {
    const Eigen::Quaterniond q(p.T_world_camera.linear());
    const Eigen::Vector3d t = p.T_world_camera.translation();
    os << std::fixed << std::setprecision(6) << p.stamp_s << std::defaultfloat << std::setprecision(12) << " " << t.x()
       << " " << t.y() << " " << t.z() << " " << q.x() << " " << q.y() << " " << q.z() << " " << q.w() << "\n";
  }
  return write_text(path, os.str());
}

Result<std::vector<StampedFile>> read_tum_list(const fs::path& path) {
  std::vector<StampedFile> files;
  auto st = for_each_line(path, [&](int line_no, const std::string& line) -> Status {
    std::istringstream ls(line);
    std::string stamp, file, rest;
    if (!(ls >> stamp)) return {};
    const std::string where = quoted(path) + " line " + std::to_string(line_no) + ": ";
    char* end = nullptr;
    const double t = std::strtod(stamp.c_str(), &end);
    if (end == stamp.c_str() || *end != '\0' || !std::isfinite(t)) {
      return invalid_argument(where + "timestamp '" + stamp + "' is not a number");
    }
    if (!(ls >> file)) return invalid_argument(where + "expected 'timestamp filename', found no file name");
    if (ls >> rest) return invalid_argument(where + "expected 'timestamp filename', found more ('" + rest + "')");
    files.push_back({t, file, line_no});
    return {};
  });
  if (!st) return st.error();
  if (files.empty()) return invalid_argument(quoted(path) + ": no images listed");
  return files;
}

Status write_tum_list(const fs::path& path, const std::vector<StampedFile>& files) {
  std::ostringstream os;
  os << "# timestamp filename\n" << std::fixed << std::setprecision(6);
  for (const auto& f : files) os << f.stamp_s << " " << f.file.generic_string() << "\n";
  return write_text(path, os.str());
}

Result<Intrinsics> estimate_intrinsics(const Cloud& cloud) {
  if (cloud.height <= 1) return invalid_argument("intrinsics can only be recovered from an organized cloud");
  // Two independent line fits, u against x/z and v against y/z, over every second pixel (a
  // quarter of a VGA frame is plenty for four parameters).
  double su = 0, sa = 0, saa = 0, sau = 0, sv = 0, sb = 0, sbb = 0, sbv = 0;
  std::size_t n = 0;
  for (std::uint32_t v = 0; v < cloud.height; v += 2) {
    for (std::uint32_t u = 0; u < cloud.width; u += 2) {
      const PointT& p = cloud.at(u, v);
      if (!is_valid(p) || p.z <= 0) continue;
      const double a = p.x / p.z, b = p.y / p.z;
      su += u; sa += a; saa += a * a; sau += a * u;
      sv += v; sb += b; sbb += b * b; sbv += b * v;
      ++n;
    }
  }
  if (n < 100) return invalid_argument("too few valid points (" + std::to_string(n) + ") to recover intrinsics");
  const double dn = static_cast<double>(n);
  const double da = dn * saa - sa * sa, db = dn * sbb - sb * sb;
  if (da <= 0 || db <= 0) return invalid_argument("the cloud's points do not spread enough to recover intrinsics");
  Intrinsics K;
  K.fx = (dn * sau - sa * su) / da;
  K.cx = (su - K.fx * sa) / dn;
  K.fy = (dn * sbv - sb * sv) / db;
  K.cy = (sv - K.fy * sb) / dn;
  K.width = static_cast<int>(cloud.width);
  K.height = static_cast<int>(cloud.height);
  double worst = 0;
  for (std::uint32_t v = 0; v < cloud.height; v += 7) {
    for (std::uint32_t u = 0; u < cloud.width; u += 7) {
      const PointT& p = cloud.at(u, v);
      if (!is_valid(p) || p.z <= 0) continue;
      worst = std::max({worst, std::abs(K.fx * p.x / p.z + K.cx - u), std::abs(K.fy * p.y / p.z + K.cy - v)});
    }
  }
  if (!K.valid() || worst > 0.5) {
    return invalid_argument("the organized cloud is not a pinhole projection (worst residual " + std::to_string(worst) +
                            " px); give the intrinsics explicitly");
  }
  return K;
}

}  // namespace scenewatch::io
