// Steps 2-4 of the hand detector (hand_candidates.h): skin components, their shape, where each
// enters the view, what it holds and where its hand is, and how confident that makes us.
#include "hand_candidates.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <Eigen/Eigenvalues>
#include <opencv2/imgproc.hpp>

namespace scenewatch::foreground {
namespace {

/// An end of the arm: its cells within this distance of the extreme along the principal axis.
constexpr double kEndSlabM = 0.04;
/// A free arm lying on the table is not one: at most this fraction of it near a support plane.
constexpr double kFreeArmMaxOnSupport = 0.3;
constexpr float kNearSupportM = 0.03f;
constexpr double kFreeArmMaxContact = 0.1;  ///< of its outline continuous with a support plane
/// At most this fraction of an arm's cells lies within the border margin.
constexpr double kMaxBorderFraction = 0.5;
/// Cells this far under the table plane are under the table; an arm has at most this fraction there.
constexpr float kBelowTableM = 0.03f;
constexpr double kMaxBelowTableFraction = 0.5;
/// Skin brighter or darker than the arm's base by more than this factor is not the same skin.
constexpr float kMaxToneRatio = 2.5f;

/// What steps 3-4 look at for every component.
struct Context {
  const Grid& g;
  const SkinCells& skin;
  const SupportCells& supports;
  const HandConfig& config;
  float jump = 0;
  int margin = 0;
  std::vector<int> component;  ///< per cell: its skin component (1-based), 0 for none
  std::vector<int> scratch;    ///< marks for grow(), a fresh id per growth
  int scratch_id = 0;
};

/// A component's cells along its principal axis.
struct ArmAxis {
  std::vector<double> t;
  double t_min = 0, t_max = 0;
};

// 2. Skin components: skin cells off the planes, neighbours joined only when their depths differ
// by less than depth_jump_m.
std::vector<std::vector<int>> skin_components(Context& x) {
  const Grid& g = x.g;
  const std::size_t n = g.p.size();
  const std::vector<std::uint8_t>& skin = x.skin.mask;
  const cv::Mat& on_support = x.supports.on_support;
  std::vector<int>& component = x.component;
  component.assign(n, 0);
  std::vector<std::vector<int>> components;
  for (std::size_t c = 0; c < n; ++c) {
    if (component[c] != 0 || !g.valid[c] || !skin[c] || on_support.data[c]) continue;
    const int id = static_cast<int>(components.size()) + 1;
    components.push_back(grow(g, {static_cast<int>(c)}, x.jump, component, id,
                              [&](int i) { return skin[i] && !on_support.data[i]; }));
  }
  return components;
}

// 3. Metric area from depth and 3D principal axes: elongation, length and width. False when the
// component is not arm-like.
bool measure_arm(const Grid& g, const std::vector<int>& cells, double cell_side, const HandConfig& config,
                 Candidate& cand, ArmAxis& along) {
  for (int i : cells) cand.area_m2 += std::pow(g.p[i].z() * cell_side, 2);
  if (cand.area_m2 < config.min_hand_area_m2 || cand.area_m2 > config.max_hand_area_m2) return false;

  const Eigen::Vector3d mean = centroid_of(g, cells);
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (int i : cells) {
    const Eigen::Vector3d q = g.p[i].cast<double>() - mean;
    cov += q * q.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(cov / static_cast<double>(cells.size()));
  const Eigen::Vector3d lambda = solver.eigenvalues();  // ascending
  const Eigen::Vector3d axis = solver.eigenvectors().col(2);
  cand.elongation = std::sqrt(lambda(2) / std::max(lambda(1), 1e-12));
  cand.width_m = std::sqrt(12.0 * std::max(0.0, lambda(1)));
  // A sliver (a bright edge along the image's top, a board's edge, a chair's slat) is narrower
  // than any forearm.
  if (cand.width_m < config.min_arm_width_m) return false;
  double t_min = std::numeric_limits<double>::infinity(), t_max = -t_min;
  std::vector<double> t(cells.size());
  for (std::size_t k = 0; k < cells.size(); ++k) {
    t[k] = (g.p[cells[k]].cast<double>() - mean).dot(axis);
    t_min = std::min(t_min, t[k]);
    t_max = std::max(t_max, t[k]);
  }
  cand.length_m = t_max - t_min;
  if (cand.elongation < config.min_elongation || cand.length_m < config.min_arm_length_m ||
      cand.length_m > config.max_arm_length_m) {
    return false;
  }
  along.t.swap(t);
  along.t_min = t_min;
  along.t_max = t_max;
  return true;
}

// Legs (bare, or trousers of a skin-like colour) are under the table; a hand working on it is
// above its plane. tables[0] is the largest horizontal plane; its normal points towards the
// camera, which looks down on it.
bool under_table(const Grid& g, const std::vector<int>& cells, const std::vector<SupportPlane>& tables) {
  if (tables.empty()) return false;
  std::size_t below = 0;
  for (int i : cells) below += tables[0].distance(g.p[i]) < -kBelowTableM;
  return below > kMaxBelowTableFraction * cells.size();
}

// Through a body: grow from each end of the arm over depth-continuous pixels off the support
// planes; the end whose growth reaches the border is where the arm enters.
void enter_through_body(Context& x, const std::vector<int> (&ends)[2], Candidate& cand) {
  const Grid& g = x.g;
  const HandConfig& config = x.config;
  const std::vector<std::uint8_t>& skin = x.skin.mask;
  const cv::Mat& near_support = x.supports.near_support;
  // When both ends reach the border (one through a held object and a table edge), the arm
  // enters at the end nearer the border: arms come from outside the view.
  double best_border_distance = std::numeric_limits<double>::infinity();
  for (int e = 0; e < 2; ++e) {
    const Eigen::Vector3d end_point = centroid_of(g, ends[e]);
    const int id = ++x.scratch_id;
    bool reaches = false;
    const std::vector<int> body = grow(g, ends[e], x.jump, x.scratch, id, [&](int i) {
      // Not through skin: a skin-coloured part of a held object would otherwise reach the
      // border through the hand and arm that hold it.
      if (x.component[i] != 0 || skin[i] || near_support.data[i]) return false;
      if (g.p[i].z() > config.person_max_range_m) return false;
      if ((g.p[i].cast<double>() - end_point).norm() > config.person_max_extent_m) return false;
      if (g.on_border(i, x.margin)) reaches = true;
      return true;
    });
    const double border_distance = distance_to_border(g, ends[e]);
    if (reaches && border_distance < best_border_distance) {
      best_border_distance = border_distance;
      cand.entry = Entry::kBody;
      cand.entry_point = end_point;
    }
  }
}

// Not lying on the table: little of it near the plane, and its outline not continuous in depth
// with the plane (an object's foot). A held-up arm is separated from the table by a depth jump.
bool lies_free(const Context& x, const std::vector<int>& cells) {
  const Grid& g = x.g;
  const std::vector<int>& component = x.component;
  const cv::Mat& on_support = x.supports.on_support;
  std::size_t near = 0, outline = 0, contact = 0;
  const int own = component[cells.front()];
  for (int i : cells) {
    near += x.supports.plane_distance[i] < kNearSupportM;
    const int cu = i % g.w, cv = i / g.w;
    bool on_outline = false, touches = false;
    for (const auto& [du, dv] : {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}}) {
      const int nu = cu + du, nv = cv + dv;
      if (nu < 0 || nv < 0 || nu >= g.w || nv >= g.h) continue;
      const int nb = nv * g.w + nu;
      if (component[nb] == own) continue;
      on_outline = true;
      touches |= g.valid[nb] && on_support.data[nb] && std::abs(g.p[nb].z() - g.p[i].z()) < x.jump;
    }
    outline += on_outline;
    contact += touches;
  }
  return near <= kFreeArmMaxOnSupport * cells.size() && contact <= kFreeArmMaxContact * outline;
}

// 3. Where the arm enters: at the image border directly, or through a depth-continuous body (off
// the planes) that reaches the border from one end of the arm, or - for a long, clearly elongated
// arm off the table - at its end nearer the border ("free arm", as the simulator's forearm that
// ends in mid-air). False when the component is a strip along the border; cand.entry stays kNone
// when it enters nowhere.
bool find_entry(Context& x, const std::vector<int>& cells, const ArmAxis& along, Candidate& cand) {
  const Grid& g = x.g;
  const HandConfig& config = x.config;
  std::vector<int> border;
  for (int i : cells) {
    if (g.on_border(i, x.margin)) border.push_back(i);
  }
  // An arm crosses the border; a strip along it (a bright edge of the ceiling) lies on it.
  if (border.size() > kMaxBorderFraction * cells.size()) return false;
  if (border.size() >= 2) {
    cand.entry = Entry::kBorder;
    cand.entry_point = centroid_of(g, border);
    return true;
  }
  std::vector<int> ends[2];
  for (std::size_t k = 0; k < cells.size(); ++k) {
    if (along.t[k] <= along.t_min + kEndSlabM) ends[0].push_back(cells[k]);
    if (along.t[k] >= along.t_max - kEndSlabM) ends[1].push_back(cells[k]);
  }
  enter_through_body(x, ends, cand);
  if (cand.entry == Entry::kNone && cand.elongation >= config.free_arm_min_elongation &&
      cand.length_m >= config.free_arm_min_length_m && lies_free(x, cells)) {
    // No body in view: the arm comes from outside the image, so it enters at its end nearer
    // the border.
    cand.entry = Entry::kFree;
    cand.entry_point = centroid_of(g, ends[distance_to_border(g, ends[0]) <= distance_to_border(g, ends[1]) ? 0 : 1]);
  }
  return true;
}

// 4. Skin of another tone in the far half is what the hand holds (a plush toy's light face in
// dark fingers, touching them in colour and depth): it leaves the arm, with the dilated rim
// around it, before the hand proper is measured. `reach`: per cell, its distance from the entry.
void drop_held_skin(const Context& x, Candidate& cand, std::vector<double>& reach, double& reach_max) {
  const Grid& g = x.g;
  const std::vector<std::uint8_t>& skin_colour = x.skin.colour;
  const std::vector<float>& luma = x.skin.luma;
  const int dilation_radius = x.skin.dilation_radius;
  std::vector<float> base;
  for (std::size_t k = 0; k < cand.cells.size(); ++k) {
    if (skin_colour[cand.cells[k]] && reach[k] < 0.5 * reach_max) base.push_back(luma[cand.cells[k]]);
  }
  if (base.size() < kMinComponentCells) return;
  std::nth_element(base.begin(), base.begin() + base.size() / 2, base.end());
  const float tone = base[base.size() / 2];
  cv::Mat foreign(g.h, g.w, CV_8U, cv::Scalar(0));
  bool any = false;
  for (std::size_t k = 0; k < cand.cells.size(); ++k) {
    const int i = cand.cells[k];
    const float ratio = luma[i] / tone;
    if (skin_colour[i] && reach[k] >= 0.5 * reach_max && (ratio > kMaxToneRatio || ratio < 1.0f / kMaxToneRatio)) {
      foreign.data[i] = 1;
      any = true;
    }
  }
  if (!any) return;
  cv::Mat rim;
  cv::dilate(foreign, rim, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * dilation_radius + 3, 2 * dilation_radius + 3)));
  std::vector<int> kept;
  std::vector<double> kept_reach;
  reach_max = 0;
  for (std::size_t k = 0; k < cand.cells.size(); ++k) {
    const int i = cand.cells[k];
    if (foreign.data[i] || (rim.data[i] && !skin_colour[i])) continue;
    kept.push_back(i);
    kept_reach.push_back(reach[k]);
    reach_max = std::max(reach_max, reach[k]);
  }
  cand.cells.swap(kept);
  reach.swap(kept_reach);
}

// 4. The hand proper is the part farthest from the entry in 3D (tip_length_m); the body is grown
// from the arm's base only, well away from the hand and what it holds.
void split_tip_and_base(const std::vector<double>& reach, double reach_max, const HandConfig& config, Candidate& cand) {
  for (std::size_t k = 0; k < cand.cells.size(); ++k) {
    if (reach[k] >= reach_max - config.tip_length_m) cand.tip_cells.push_back(cand.cells[k]);
    if (reach[k] < reach_max - config.tip_length_m - config.tip_clearance_m) cand.base_cells.push_back(cand.cells[k]);
  }
  if (cand.base_cells.empty()) {
    for (std::size_t k = 0; k < cand.cells.size(); ++k) {
      if (reach[k] < reach_max - config.tip_length_m) cand.base_cells.push_back(cand.cells[k]);
    }
  }
}

// Score: how it enters (the border is the strongest evidence, a free arm the weakest), how
// arm-like and how long it is (a hand with forearm is 0.3-0.5 m; a patch of skin-coloured
// trousers or a face 0.1-0.25 m).
double arm_score(const Candidate& cand) {
  const double entry_score = cand.entry == Entry::kBorder ? 1.0 : cand.entry == Entry::kBody ? 0.9 : 0.6;
  const double elongation_score = std::clamp((cand.elongation - 1.0) / 4.0, 0.0, 1.0);
  const double length_score = std::clamp((cand.length_m - 0.1) / 0.3, 0.0, 1.0);
  return std::clamp(entry_score * (0.4 + 0.2 * elongation_score + 0.4 * length_score), 0.0, 1.0);
}

}  // namespace

std::vector<Candidate> find_hand_candidates(const Grid& g, const SkinCells& skin, const SupportCells& supports,
                                            const HandConfig& config) {
  Context x{g, skin, supports, config, static_cast<float>(config.depth_jump_m), config.border_margin_px, {}, {}, 0};
  const std::vector<std::vector<int>> components = skin_components(x);

  // 3-4. Which components are arms with a hand, where they enter and where their hand is.
  const double cell_side = g.step / estimate_focal_px(g);  // metres per metre of depth
  std::vector<Candidate> candidates;
  x.scratch.assign(g.p.size(), 0);
  for (const std::vector<int>& cells : components) {
    if (cells.size() < kMinComponentCells) continue;
    Candidate cand;
    cand.cells = cells;
    ArmAxis along;
    if (!measure_arm(g, cells, cell_side, config, cand, along)) continue;
    if (under_table(g, cells, supports.tables)) continue;
    if (!find_entry(x, cells, along, cand) || cand.entry == Entry::kNone) continue;

    std::vector<double> reach(cand.cells.size());
    double reach_max = 0;
    for (std::size_t k = 0; k < cand.cells.size(); ++k) {
      reach[k] = (g.p[cand.cells[k]].cast<double>() - cand.entry_point).norm();
      reach_max = std::max(reach_max, reach[k]);
    }
    drop_held_skin(x, cand, reach, reach_max);
    if (cand.cells.size() < kMinComponentCells) continue;
    split_tip_and_base(reach, reach_max, config, cand);
    cand.tip = centroid_of(g, cand.tip_cells);
    cand.score = arm_score(cand);
    candidates.push_back(std::move(cand));
  }
  std::stable_sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) { return a.score > b.score; });
  return candidates;
}

}  // namespace scenewatch::foreground
