#include "frame_trace.h"

#include <algorithm>
#include <cmath>
#include <future>

#include "ray_cast.h"

namespace scenewatch::background {

using octomap::OcTreeKey;

namespace {
// Frames of at least this many points (after the stride) are traced on two threads: a VGA frame
// has 300000 (77000 at stride 2), a 320x240 frame 77000. Even a Kinect tabletop at 2 cm gains
// (4.5-4.8 against 5.3-5.7 ms); smaller frames stay on the calling thread.
constexpr std::size_t kParallelPoints = 40000;
}  // namespace

// What both halves share: the frame, the sensor, and the box every key of the frame lies in.
struct FrameTrace::Frame {
  Frame(const octomap::ColorOcTree& tree_, const Cloud& cloud_, const Eigen::Isometry3f& T_, const TraceSettings& settings_)
      : tree(tree_), cloud(cloud_), T(T_), settings(settings_), origin_f(T_.translation()),
        origin(origin_f.x(), origin_f.y(), origin_f.z()), key_factor(1.0 / tree_.getResolution()),
        key_centre(1 << (tree_.getTreeDepth() - 1)) {}

  const octomap::ColorOcTree& tree;
  const Cloud& cloud;
  const Eigen::Isometry3f& T;
  const TraceSettings& settings;
  Eigen::Vector3f origin_f;
  octomap::point3d origin;
  OcTreeKey origin_key;
  std::size_t width = 1, step = 1;  // pixels per row (the whole cloud if not organized), stride
  OcTreeKey lo, hi;
  double key_factor = 1.0;  // 1 / resolution, as OctoMap's resolution_factor
  int key_centre = 32768;   // 2^(depth - 1), OctoMap's tree_max_val

  // Calls f(point) for the frame's points in columns [first, last) of every step-th row.
  template <typename F>
  void for_each_point(std::size_t first, std::size_t last, F&& f) const {
    const std::size_t n = cloud.size();
    for (std::size_t row = 0; row < n; row += width * step)
      for (std::size_t i = row + first; i < std::min(row + last, n); i += step) f(cloud.points[i]);
  }
  // The world point of a valid camera point, cut at max range; `cut` says whether it was, `range`
  // is its distance from the sensor before the cut.
  Eigen::Vector3f world(const PointT& p, bool& cut, float& range) const {
    const Eigen::Vector3f w = T * p.getVector3fMap();
    const Eigen::Vector3f d = w - origin_f;
    range = d.norm();
    const double max_range = settings.max_range_m;
    cut = max_range > 0 && range > max_range;
    return cut ? Eigen::Vector3f(origin_f + d * static_cast<float>(max_range / range)) : w;
  }
  // OctoMap's coordToKeyChecked(point3d): floor(coordinate / resolution) + 2^(depth - 1) per
  // axis, inside [0, 2^depth). The floor is written out: the library calls libm's floor() three
  // times per point (no SSE4.1 in an x86-64 baseline build); written out, a room's half frame
  // takes 3-4 ms here instead of 6-7.
  bool key_of(const Eigen::Vector3f& w, OcTreeKey& key) const {
    for (int i = 0; i < 3; ++i) {
      const double a = key_factor * static_cast<double>(w[i]);
      if (!(a > -2147483648.0 && a < 2147483647.0)) return false;  // also NaN
      int f = static_cast<int>(a);  // towards zero
      if (a < f) --f;
      const int k = f + key_centre;
      if (k < 0 || k >= 2 * key_centre) return false;
      key[i] = static_cast<octomap::key_type>(k);
    }
    return true;
  }
  std::vector<double> column_work;  // per column of the image, the volume its rays sweep

  // The column that splits the frame into halves of equal work: the voxels a pixel's rays free
  // grow with the volume of its pyramid, range^3. A room's deep half would otherwise take twice
  // as long as its near one. Rounded to a column the stride visits.
  std::size_t balanced_split() const {
    double total = 0.0;
    for (double w : column_work) total += w;
    double sum = 0.0;
    std::size_t c = 0;
    while (c + 1 < width && sum + column_work[c] < total / 2) sum += column_work[c++];
    return c / step * step;
  }
  // The key box of the sensor and every (cut) point, over which the ray sets of both halves are
  // laid out (so that they merge block by block), and each column's work.
  void find_box() {
    Eigen::Vector3f min = origin_f, max = origin_f;
    column_work.assign(width, 0.0);
    const PointT* first = cloud.points.data();
    for_each_point(0, width, [&](const PointT& p) {
      if (!is_valid(p)) return;
      bool cut = false;
      float r = 0.0f;
      const Eigen::Vector3f w = world(p, cut, r);
      min = min.cwiseMin(w);
      max = max.cwiseMax(w);
      if (cut) r = static_cast<float>(settings.max_range_m);
      column_work[static_cast<std::size_t>(&p - first) % width] += static_cast<double>(r * r * r);
    });
    // coordToKey (floor(coordinate / resolution) + 2^(depth - 1)) is monotonic: the corners'
    // keys bound every point's key. Points outside the map's extent are dropped later; the box
    // is clamped to it.
    for (int i = 0; i < 3; ++i) {
      const double a = std::floor(key_factor * static_cast<double>(min[i])) + key_centre;
      const double b = std::floor(key_factor * static_cast<double>(max[i])) + key_centre;
      lo[i] = static_cast<octomap::key_type>(std::clamp(a, 0.0, 65535.0));
      hi[i] = static_cast<octomap::key_type>(std::clamp(b, 0.0, 65535.0));
    }
  }
};

void FrameTrace::trace_columns(const Frame& f, std::size_t first, std::size_t last, Half& half) {
  const octomap::ColorOcTree& tree = f.tree;
  // 1. One endpoint per voxel, with the mean colour of its pixels; rays beyond max range are cut
  //    and end in a voxel that is freed, not hit. Neighbouring pixels mostly end in one voxel:
  //    their colours are summed in a run that goes into the hash map once, when the voxel changes.
  half.ends.clear();
  half.clipped.clear();
  half.points = 0;
  OcTreeKey key;
  std::uint64_t run_key = 0;
  ColorSum run;
  auto flush = [&] {
    if (run.n == 0) return;
    half.ends.add(run_key, run);
    run = ColorSum{};
  };
  f.for_each_point(first, last, [&](const PointT& p) {
    if (!is_valid(p)) return;
    ++half.points;
    bool cut = false;
    float range = 0.0f;
    const Eigen::Vector3f w = f.world(p, cut, range);
    if (!f.key_of(w, key)) return;
    const std::uint64_t k = pack_key(key);
    if (cut) {
      half.clipped.push_back(k);
      return;
    }
    if (k != run_key) {
      flush();
      run_key = k;
    }
    run.r += p.r;
    run.g += p.g;
    run.b += p.b;
    ++run.n;
  });
  flush();
  std::sort(half.clipped.begin(), half.clipped.end());
  half.clipped.erase(std::unique(half.clipped.begin(), half.clipped.end()), half.clipped.end());

  // 2. Rays from the sensor to each endpoint voxel's centre, then the cut rays.
  half.rays.reset(f.lo, f.hi);
  const int stop_after = f.settings.ray_stop_after;
  half.ends.for_each([&](const OcTreeKey& end) {
    half.rays.insert_end(end);
    if (stop_after > 0) cast_ray_back(tree, f.origin, f.origin_key, tree.keyToCoord(end), end, stop_after, half.rays);
    else cast_ray(tree, f.origin, f.origin_key, tree.keyToCoord(end), end, half.rays);
  });
  for (std::uint64_t k : half.clipped) {
    const OcTreeKey end = unpack_key(k);
    cast_ray(tree, f.origin, f.origin_key, tree.keyToCoord(end), end, half.rays);
    half.rays.insert_free(end);  // a cut ray frees its last voxel too: nothing was seen there
  }
  half.ends.sort_by_morton();
}

std::size_t FrameTrace::trace(const octomap::ColorOcTree& tree, const Cloud& points_camera, const Eigen::Isometry3f& T,
                              const TraceSettings& settings) {
  Frame f(tree, points_camera, T, settings);
  if (!tree.coordToKeyChecked(f.origin, f.origin_key)) {
    clear();
    return 0;
  }
  const std::size_t n = points_camera.size();
  const bool organized = points_camera.height > 1 && points_camera.width > 0;
  f.width = organized ? points_camera.width : std::max<std::size_t>(n, 1);
  f.step = organized && settings.stride > 1 ? static_cast<std::size_t>(settings.stride) : 1;
  f.find_box();
  for (int i = 0; i < 3; ++i) {
    f.lo[i] = std::min(f.lo[i], f.origin_key[i]);
    f.hi[i] = std::max(f.hi[i], f.origin_key[i]);
  }
  if (n / (f.step * f.step) < kParallelPoints) {
    trace_columns(f, 0, f.width, halves_[0]);
    return halves_[0].points;
  }
  // Split at a column the stride visits, so that the halves see the same pixels as one pass.
  const std::size_t split = f.balanced_split();
  auto right = std::async(std::launch::async, [&] { trace_columns(f, split, f.width, halves_[1]); });
  trace_columns(f, 0, split, halves_[0]);
  right.get();
  halves_[0].rays.merge(halves_[1].rays);
  halves_[0].ends.merge(halves_[1].ends);
  return halves_[0].points + halves_[1].points;
}

void FrameTrace::clear() {
  for (Half& h : halves_) {
    h.rays.reset(OcTreeKey(0, 0, 0), OcTreeKey(0, 0, 0));
    h.ends.clear();
    h.clipped.clear();
    h.points = 0;
  }
}

}  // namespace scenewatch::background
