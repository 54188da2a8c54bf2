#include "scenewatch/background/appearance.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <string>

#include "scenewatch/io/image_io.h"
#include "scenewatch/io/rgbd.h"

namespace scenewatch::background {
namespace fs = std::filesystem;

namespace {

constexpr float kNearM = 0.05f;  // triangles with a vertex closer than this to the camera are skipped

/// One keyframe's part of the mesh, with the pixel each vertex came from.
struct Patch {
  ColoredMesh mesh;
  std::vector<std::uint32_t> vertex_pixel;
  std::size_t bytes() const {
    return mesh.vertices.size() * (sizeof(Eigen::Vector3f) + 3 + sizeof(std::uint32_t)) +
           mesh.triangles.size() * sizeof(mesh.triangles[0]);
  }
};

struct Entry {
  std::shared_ptr<const Keyframe> keyframe;
  std::shared_ptr<const Patch> patch;
  std::size_t bytes() const { return keyframe->bytes() + patch->bytes(); }
};

Patch triangulate(const Keyframe& kf, int stride, double max_jump) {
  Patch patch;
  const int w = kf.depth.width, h = kf.depth.height;
  const int gw = (w - 1) / stride + 1, gh = (h - 1) / stride + 1;
  std::vector<std::int32_t> index(static_cast<std::size_t>(gw) * gh, -1);
  std::vector<float> z(index.size(), 0.0f);
  const Eigen::Isometry3f T = kf.T_world_camera.cast<float>();
  const Intrinsics& K = kf.intrinsics;
  for (int gy = 0; gy < gh; ++gy) {
    for (int gx = 0; gx < gw; ++gx) {
      const int u = gx * stride, v = gy * stride;
      const std::size_t pix = static_cast<std::size_t>(v) * w + u;
      const std::uint16_t mm = kf.depth.depth_mm[pix];
      if (mm == 0 || mm == 65535) continue;
      const float d = mm * 0.001f;
      const Eigen::Vector3f pc(static_cast<float>((u - K.cx) / K.fx) * d, static_cast<float>((v - K.cy) / K.fy) * d, d);
      index[static_cast<std::size_t>(gy) * gw + gx] = static_cast<std::int32_t>(patch.mesh.vertices.size());
      z[static_cast<std::size_t>(gy) * gw + gx] = d;
      patch.mesh.vertices.push_back(T * pc);
      patch.mesh.colors.push_back({kf.color.rgb[3 * pix], kf.color.rgb[3 * pix + 1], kf.color.rgb[3 * pix + 2]});
      patch.vertex_pixel.push_back(static_cast<std::uint32_t>(pix));
    }
  }
  const auto joined = [&](std::size_t a, std::size_t b) {
    return std::abs(z[a] - z[b]) <= max_jump * std::min(z[a], z[b]);
  };
  const auto add = [&](std::size_t a, std::size_t b, std::size_t c) {
    if (index[a] < 0 || index[b] < 0 || index[c] < 0) return;
    if (!joined(a, b) || !joined(b, c) || !joined(a, c)) return;
    patch.mesh.triangles.push_back({static_cast<std::uint32_t>(index[a]), static_cast<std::uint32_t>(index[b]),
                                    static_cast<std::uint32_t>(index[c])});
  };
  for (int gy = 0; gy + 1 < gh; ++gy) {
    for (int gx = 0; gx + 1 < gw; ++gx) {
      const std::size_t i00 = static_cast<std::size_t>(gy) * gw + gx, i10 = i00 + 1, i01 = i00 + gw, i11 = i01 + 1;
      // Split the cell along the diagonal whose depths agree better.
      if (index[i00] >= 0 && index[i11] >= 0 && index[i10] >= 0 && index[i01] >= 0 &&
          std::abs(z[i10] - z[i01]) < std::abs(z[i00] - z[i11])) {
        add(i00, i01, i10);
        add(i10, i01, i11);
      } else {
        add(i00, i01, i11);
        add(i00, i11, i10);
      }
    }
  }
  return patch;
}

// Four floats, and the lane masks their comparisons give (GCC's and Clang's vector extensions:
// SSE on x86-64, NEON on arm64, plain code elsewhere).
using F4 = float __attribute__((vector_size(16)));
using I4 = std::int32_t __attribute__((vector_size(16)));
constexpr F4 kLanes = {0.0f, 1.0f, 2.0f, 3.0f};

/// Z-buffers one mesh into `inverse_depth` (out's size; 1/z, 0 = empty), keeping the nearest
/// surface. Inverse depth is affine across a projected triangle, so the nearest surface is the
/// largest value and a pixel costs no division (the divisions go to `invert_depths`, once per
/// pixel, not once per covered pixel of every triangle).
void rasterize_inverse(const ColoredMesh& mesh, const Pose& T_world_camera, const Intrinsics& K, int w, int h,
                       float* inverse_depth) {
  const Eigen::Isometry3f T = T_world_camera.inverse().cast<float>();
  const float fx = static_cast<float>(K.fx), fy = static_cast<float>(K.fy);
  const float cx = static_cast<float>(K.cx), cy = static_cast<float>(K.cy);
  const std::size_t nv = mesh.vertices.size();
  std::vector<float> pu(nv), pv(nv), piz(nv);
  for (std::size_t i = 0; i < nv; ++i) {
    const Eigen::Vector3f p = T * mesh.vertices[i];
    if (p.z() < kNearM) {
      piz[i] = 0.0f;
      continue;
    }
    const float iz = 1.0f / p.z();
    pu[i] = fx * p.x() * iz + cx;
    pv[i] = fy * p.y() * iz + cy;
    piz[i] = iz;
  }
  for (const auto& t : mesh.triangles) {
    const std::uint32_t a = t[0], b = t[1], c = t[2];
    if (piz[a] == 0.0f || piz[b] == 0.0f || piz[c] == 0.0f) continue;
    const float ax = pu[a], ay = pv[a], bx = pu[b], by = pv[b], qx = pu[c], qy = pv[c];
    const int x0 = std::max(0, static_cast<int>(std::ceil(std::min({ax, bx, qx}))));
    const int x1 = std::min(w - 1, static_cast<int>(std::floor(std::max({ax, bx, qx}))));
    const int y0 = std::max(0, static_cast<int>(std::ceil(std::min({ay, by, qy}))));
    const int y1 = std::min(h - 1, static_cast<int>(std::floor(std::max({ay, by, qy}))));
    if (x0 > x1 || y0 > y1) continue;
    const float area = (bx - ax) * (qy - ay) - (by - ay) * (qx - ax);
    if (std::abs(area) < 1e-9f) continue;
    const float inv_area = 1.0f / area;
    // Barycentric weights as affine functions of (x, y).
    const float w0x = (by - qy) * inv_area, w0y = (qx - bx) * inv_area;
    const float w1x = (qy - ay) * inv_area, w1y = (ax - qx) * inv_area;
    const float w0c = ((bx - x0) * (qy - y0) - (by - y0) * (qx - x0)) * inv_area;
    const float w1c = ((qx - x0) * (ay - y0) - (qy - y0) * (ax - x0)) * inv_area;
    const float iza = piz[a], izb = piz[b], izc = piz[c];
    constexpr float kEps = -1e-5f;
    const int n = x1 - x0 + 1;
    for (int y = y0; y <= y1; ++y) {
      const float w0r = w0c + w0y * static_cast<float>(y - y0), w1r = w1c + w1y * static_cast<float>(y - y0);
      float* row = inverse_depth + static_cast<std::size_t>(y) * w + x0;
      // Each pixel's weights from the row's start, not from the pixel before (no chain of
      // additions), four pixels at a time: most triangles of a keyframe's patch span a few
      // pixels, so a row is mostly one step. The same arithmetic as one pixel at a time below.
      int k = 0;
      for (; k < n && x0 + k + 4 <= w; k += 4) {
        const F4 dx = kLanes + static_cast<float>(k);
        const F4 w0 = w0r + w0x * dx, w1 = w1r + w1x * dx, w2 = 1.0f - w0 - w1;
        const F4 iz = w0 * iza + w1 * izb + w2 * izc;
        F4 old;
        std::memcpy(&old, row + k, sizeof old);
        const I4 nearer = (dx < static_cast<float>(n)) & (w0 >= kEps) & (w1 >= kEps) & (w2 >= kEps) & (iz > old);
        const F4 out = nearer ? iz : old;
        std::memcpy(row + k, &out, sizeof out);
      }
      for (; k < n; ++k) {
        const float dx = static_cast<float>(k);
        const float w0 = w0r + w0x * dx, w1 = w1r + w1x * dx, w2 = 1.0f - w0 - w1;
        const float iz = w0 * iza + w1 * izb + w2 * izc;
        if (w0 >= kEps && w1 >= kEps && w2 >= kEps && iz > row[k]) row[k] = iz;
      }
    }
  }
}

/// Depths from the inverse depths `rasterize_inverse` left (0 stays empty).
void invert_depths(DepthMap* d) {
  for (float& v : d->depth_m) v = v > 0.0f ? 1.0f / v : 0.0f;
}

DepthMap empty_depth(const Intrinsics& K);

/// The depth map of meshes, nearest surface first.
template <typename Meshes>
DepthMap rasterize(const Meshes& meshes, const Pose& T_world_camera, const Intrinsics& K) {
  DepthMap out = empty_depth(K);
  for (const ColoredMesh* mesh : meshes) rasterize_inverse(*mesh, T_world_camera, K, out.width, out.height, out.depth_m.data());
  invert_depths(&out);
  return out;
}

DepthMap empty_depth(const Intrinsics& K) {
  DepthMap d;
  d.width = K.width;
  d.height = K.height;
  d.depth_m.assign(static_cast<std::size_t>(K.width) * K.height, 0.0f);
  return d;
}

Status check_keyframe(const Keyframe& kf) {
  const Intrinsics& K = kf.intrinsics;
  if (!K.valid()) return invalid_argument("keyframe: intrinsics are not valid");
  if (kf.color.width != K.width || kf.color.height != K.height || kf.depth.width != K.width ||
      kf.depth.height != K.height) {
    return invalid_argument("keyframe: colour " + std::to_string(kf.color.width) + "x" +
                            std::to_string(kf.color.height) + ", depth " + std::to_string(kf.depth.width) + "x" +
                            std::to_string(kf.depth.height) + " and intrinsics " + std::to_string(K.width) + "x" +
                            std::to_string(K.height) + " disagree");
  }
  if (kf.color.rgb.size() != 3u * K.width * K.height || kf.depth.depth_mm.size() != 1u * K.width * K.height)
    return invalid_argument("keyframe: image buffers do not match their sizes");
  if (!kf.T_world_camera.matrix().allFinite()) return invalid_argument("keyframe: pose is not finite");
  return {};
}

std::string frame_stem(std::uint64_t id) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "keyframe-%06llu", static_cast<unsigned long long>(id));
  return buf;
}

}  // namespace

Status validate(const AppearanceConfig& c) {
  if (!(c.keyframe_min_translation_m > 0) && !(c.keyframe_min_rotation_deg > 0))
    return invalid_argument("appearance.keyframe_min_translation_m and keyframe_min_rotation_deg: one must be > 0");
  if (c.keyframe_min_translation_m < 0) return invalid_argument("appearance.keyframe_min_translation_m must be >= 0");
  if (c.keyframe_min_rotation_deg < 0 || c.keyframe_min_rotation_deg > 180)
    return invalid_argument("appearance.keyframe_min_rotation_deg must be in [0, 180]");
  if (c.max_keyframes < 1) return invalid_argument("appearance.max_keyframes must be >= 1");
  if (c.memory_budget_mb < 1) return invalid_argument("appearance.memory_budget_mb must be >= 1");
  if (c.mesh_stride_px < 1 || c.mesh_stride_px > 64) return invalid_argument("appearance.mesh_stride_px must be in [1, 64]");
  if (!(c.mesh_max_depth_jump > 0)) return invalid_argument("appearance.mesh_max_depth_jump must be > 0");
  if (c.depth_views < 1 || c.depth_views > 16) return invalid_argument("appearance.depth_views must be in [1, 16]");
  return {};
}

Result<Keyframe> keyframe_from_frame(const Frame& frame) {
  if (!frame.cloud) return invalid_argument(frame.source + ": no cloud");
  const Cloud& cloud = *frame.cloud;
  if (!cloud.isOrganized() || cloud.height <= 1)
    return invalid_argument(frame.source + ": keyframes and image surprise need an organized cloud (an RGB-D image)");
  if (!frame.intrinsics || !frame.intrinsics->valid())
    return invalid_argument(frame.source + ": keyframes and image surprise need camera intrinsics");
  const Intrinsics& K = *frame.intrinsics;
  if (static_cast<int>(cloud.width) != K.width || static_cast<int>(cloud.height) != K.height)
    return invalid_argument(frame.source + ": cloud is " + std::to_string(cloud.width) + "x" +
                            std::to_string(cloud.height) + " but intrinsics are for " + std::to_string(K.width) + "x" +
                            std::to_string(K.height));
  Keyframe kf;
  kf.stamp_s = frame.stamp_s;
  kf.T_world_camera = frame.pose_or_identity();
  kf.intrinsics = K;
  kf.color.width = kf.depth.width = K.width;
  kf.color.height = kf.depth.height = K.height;
  kf.color.rgb.resize(3 * cloud.size());
  kf.depth.depth_mm.assign(cloud.size(), 0);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const PointT& p = cloud[i];
    kf.color.rgb[3 * i] = p.r;
    kf.color.rgb[3 * i + 1] = p.g;
    kf.color.rgb[3 * i + 2] = p.b;
    if (is_valid(p) && p.z > 0 && p.z < 65.0f) kf.depth.depth_mm[i] = static_cast<std::uint16_t>(std::lround(p.z * 1000.0f));
  }
  return kf;
}

ViewDistance view_distance(const Pose& a, const Pose& b) {
  ViewDistance d;
  d.translation_m = (a.translation() - b.translation()).norm();
  const Eigen::AngleAxisd rel(a.linear().transpose() * b.linear());
  d.rotation_deg = std::abs(rel.angle()) * 180.0 / M_PI;
  return d;
}

struct AppearanceMemory::Impl {
  std::vector<Entry> entries;  // oldest first
  std::uint64_t next_id = 1;
  std::size_t bytes = 0;

  double normalized(const AppearanceConfig& c, const Pose& a, const Pose& b) const {
    const ViewDistance d = view_distance(a, b);
    const double t = c.keyframe_min_translation_m > 0 ? d.translation_m / c.keyframe_min_translation_m : 0.0;
    const double r = c.keyframe_min_rotation_deg > 0 ? d.rotation_deg / c.keyframe_min_rotation_deg : 0.0;
    return t + r;
  }
};

AppearanceMemory::AppearanceMemory(AppearanceConfig config) : config_(config), impl_(std::make_unique<Impl>()) {}
AppearanceMemory::~AppearanceMemory() = default;
AppearanceMemory::AppearanceMemory(AppearanceMemory&&) noexcept = default;
AppearanceMemory& AppearanceMemory::operator=(AppearanceMemory&&) noexcept = default;

bool AppearanceMemory::is_new_view(const Pose& T_world_camera) const {
  for (const Entry& e : impl_->entries) {
    const ViewDistance d = view_distance(e.keyframe->T_world_camera, T_world_camera);
    if (d.translation_m < config_.keyframe_min_translation_m && d.rotation_deg < config_.keyframe_min_rotation_deg)
      return false;
  }
  return true;
}

Result<std::uint64_t> AppearanceMemory::add(Keyframe keyframe) {
  if (auto st = check_keyframe(keyframe); !st) return st.error();
  keyframe.id = impl_->next_id++;
  const int stride = std::max(1, static_cast<int>(std::lround(config_.mesh_stride_px * keyframe.intrinsics.width / 640.0)));
  auto patch = std::make_shared<Patch>(triangulate(keyframe, stride, config_.mesh_max_depth_jump));
  Entry entry{std::make_shared<const Keyframe>(std::move(keyframe)), std::move(patch)};
  impl_->bytes += entry.bytes();
  impl_->entries.push_back(std::move(entry));
  const std::size_t budget = config_.memory_budget_mb << 20;
  while (impl_->entries.size() > 1 && (impl_->entries.size() > config_.max_keyframes || impl_->bytes > budget)) {
    // The most redundant view among all but the newest.
    std::size_t victim = 0;
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i + 1 < impl_->entries.size(); ++i) {
      double nearest = std::numeric_limits<double>::infinity();
      for (std::size_t j = 0; j < impl_->entries.size(); ++j) {
        if (j == i) continue;
        nearest = std::min(nearest, impl_->normalized(config_, impl_->entries[i].keyframe->T_world_camera,
                                                      impl_->entries[j].keyframe->T_world_camera));
      }
      if (nearest < best) {  // strict: the oldest wins ties
        best = nearest;
        victim = i;
      }
    }
    impl_->bytes -= impl_->entries[victim].bytes();
    impl_->entries.erase(impl_->entries.begin() + static_cast<std::ptrdiff_t>(victim));
  }
  return impl_->entries.back().keyframe->id;
}

Result<bool> AppearanceMemory::consider(Keyframe keyframe) {
  if (!is_new_view(keyframe.T_world_camera)) return false;
  auto id = add(std::move(keyframe));
  if (!id) return id.error();
  return true;
}

Result<std::uint64_t> AppearanceMemory::replace_nearest(Keyframe keyframe) {
  if (auto st = check_keyframe(keyframe); !st) return st.error();
  if (!impl_->entries.empty()) {
    std::size_t best = 0;
    double best_d = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < impl_->entries.size(); ++i) {
      const double d = impl_->normalized(config_, impl_->entries[i].keyframe->T_world_camera, keyframe.T_world_camera);
      if (d < best_d) {
        best_d = d;
        best = i;
      }
    }
    impl_->bytes -= impl_->entries[best].bytes();
    impl_->entries.erase(impl_->entries.begin() + static_cast<std::ptrdiff_t>(best));
  }
  return add(std::move(keyframe));
}

std::vector<std::shared_ptr<const Keyframe>> AppearanceMemory::nearest(const Pose& T_world_camera, std::size_t n) const {
  std::vector<std::pair<double, std::size_t>> ranked;
  const Eigen::Vector3d axis = T_world_camera.linear().col(2);
  for (std::size_t i = 0; i < impl_->entries.size(); ++i) {
    const Pose& kp = impl_->entries[i].keyframe->T_world_camera;
    if (kp.linear().col(2).dot(axis) <= 0.0) continue;
    ranked.emplace_back(impl_->normalized(config_, kp, T_world_camera), i);
  }
  std::sort(ranked.begin(), ranked.end());
  std::vector<std::shared_ptr<const Keyframe>> out;
  for (std::size_t k = 0; k < ranked.size() && k < n; ++k) out.push_back(impl_->entries[ranked[k].second].keyframe);
  return out;
}

DepthMap AppearanceMemory::render_depth(const Pose& T_world_camera, const Intrinsics& K) const {
  return render_depth(T_world_camera, K, nearest(T_world_camera, static_cast<std::size_t>(config_.depth_views)));
}

DepthMap AppearanceMemory::render_depth(const Pose& T_world_camera, const Intrinsics& K,
                                        const std::vector<std::shared_ptr<const Keyframe>>& from) const {
  std::vector<const ColoredMesh*> meshes;
  for (const auto& kf : from) {
    for (const Entry& e : impl_->entries) {
      if (e.keyframe == kf) meshes.push_back(&e.patch->mesh);
    }
  }
  return rasterize(meshes, T_world_camera, K);
}

ColoredMesh AppearanceMemory::mesh() const {
  ColoredMesh merged;
  for (const Entry& e : impl_->entries) {
    const Keyframe& kf = *e.keyframe;
    const Patch& patch = *e.patch;
    // Which of this patch's vertices does the mesh so far already explain?
    std::vector<char> explained(patch.mesh.vertices.size(), 0);
    if (!merged.empty()) {
      const DepthMap seen = rasterize(std::array{&merged}, kf.T_world_camera, kf.intrinsics);
      const int w = kf.depth.width, h = kf.depth.height;
      for (std::size_t v = 0; v < explained.size(); ++v) {
        // A vertex on the border of the mesh so far may fall just outside its raster: any
        // agreeing pixel of its 3x3 neighbourhood explains it.
        const std::uint32_t pix = patch.vertex_pixel[v];
        const int u0 = static_cast<int>(pix % static_cast<std::uint32_t>(w)), v0 = static_cast<int>(pix / static_cast<std::uint32_t>(w));
        const float observed = kf.depth.depth_mm[pix] * 0.001f;
        for (int dv = -1; dv <= 1 && !explained[v]; ++dv) {
          for (int du = -1; du <= 1 && !explained[v]; ++du) {
            const int uu = u0 + du, vv = v0 + dv;
            if (uu < 0 || vv < 0 || uu >= w || vv >= h) continue;
            const float rendered = seen.depth_m[static_cast<std::size_t>(vv) * w + uu];
            explained[v] = rendered > 0 && std::abs(rendered - observed) < 0.01f + 0.02f * observed;
          }
        }
      }
    }
    // Keep the triangles with an unexplained vertex, with their vertices compacted.
    std::vector<std::int64_t> remap(patch.mesh.vertices.size(), -1);
    for (const auto& t : patch.mesh.triangles) {
      if (explained[t[0]] && explained[t[1]] && explained[t[2]]) continue;
      std::array<std::uint32_t, 3> out{};
      for (int k = 0; k < 3; ++k) {
        if (remap[t[k]] < 0) {
          remap[t[k]] = static_cast<std::int64_t>(merged.vertices.size());
          merged.vertices.push_back(patch.mesh.vertices[t[k]]);
          merged.colors.push_back(patch.mesh.colors[t[k]]);
        }
        out[k] = static_cast<std::uint32_t>(remap[t[k]]);
      }
      merged.triangles.push_back(out);
    }
  }
  return merged;
}

std::vector<std::shared_ptr<const Keyframe>> AppearanceMemory::keyframes() const {
  std::vector<std::shared_ptr<const Keyframe>> out;
  for (const Entry& e : impl_->entries) out.push_back(e.keyframe);
  return out;
}

std::size_t AppearanceMemory::size() const { return impl_->entries.size(); }
std::size_t AppearanceMemory::memory_bytes() const { return impl_->bytes; }
std::size_t AppearanceMemory::triangle_count() const {
  std::size_t n = 0;
  for (const Entry& e : impl_->entries) n += e.patch->mesh.triangles.size();
  return n;
}

void AppearanceMemory::clear() {
  impl_->entries.clear();
  impl_->bytes = 0;
}

Status AppearanceMemory::save(const fs::path& dir) const {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return io_error("'" + dir.string() + "': cannot create: " + ec.message());
  for (const Entry& e : impl_->entries) {
    const Keyframe& kf = *e.keyframe;
    const fs::path stem = dir / frame_stem(kf.id);
    if (auto st = io::write_color_png(stem.string() + ".color.png", kf.color); !st) return st;
    if (auto st = io::write_depth_png(stem.string() + ".depth.png", kf.depth); !st) return st;
    if (auto st = io::write_pose_matrix(stem.string() + ".pose.txt", kf.T_world_camera); !st) return st;
    if (auto st = io::write_intrinsics(stem.string() + ".intrinsics.txt", kf.intrinsics); !st) return st;
  }
  return {};
}

Status AppearanceMemory::load(const fs::path& dir) {
  AppearanceMemory loaded(config_);
  std::error_code ec;
  if (fs::is_directory(dir, ec)) {
    std::map<std::string, fs::path> stems;  // sorted: ids in order
    for (const auto& entry : fs::directory_iterator(dir, ec)) {
      const std::string name = entry.path().filename().string();
      const std::string suffix = ".color.png";
      if (name.rfind("keyframe-", 0) == 0 && name.size() > suffix.size() &&
          name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0) {
        stems[name.substr(0, name.size() - suffix.size())] = dir / name.substr(0, name.size() - suffix.size());
      }
    }
    for (const auto& [name, stem] : stems) {
      Keyframe kf;
      auto color = io::read_color_png(stem.string() + ".color.png");
      if (!color) return color.error();
      auto depth = io::read_depth_png(stem.string() + ".depth.png");
      if (!depth) return depth.error();
      auto pose = io::read_pose_matrix(stem.string() + ".pose.txt");
      if (!pose) return pose.error();
      auto K = io::read_intrinsics(stem.string() + ".intrinsics.txt");
      if (!K) return K.error();
      kf.color = std::move(*color);
      kf.depth = std::move(*depth);
      kf.T_world_camera = *pose;
      kf.intrinsics = *K;
      kf.intrinsics.width = kf.depth.width;
      kf.intrinsics.height = kf.depth.height;
      auto id = loaded.add(std::move(kf));
      if (!id) return Error{id.error().code, "'" + stem.string() + "': " + id.error().message};
    }
  }
  *impl_ = std::move(*loaded.impl_);
  return {};
}

DepthMap render_mesh_depth(const ColoredMesh& mesh, const Pose& T_world_camera, const Intrinsics& K) {
  return rasterize(std::array{&mesh}, T_world_camera, K);
}

}  // namespace scenewatch::background
