// Hands, arms and the person in an organized RGB-D frame.
//
// Steps, on a grid of every grid_step-th pixel (frame_grid.h; labels are upsampled at the end):
//  1. skin mask (skin_model.h), closed and dilated; large planes (support_plane.h): table and
//     floor (near-horizontal), then walls;
//  2. connected components of skin cells off those planes, neighbours joined only when their
//     depths differ by less than depth_jump_m;
//  3. per component: metric area from depth, 3D principal axes (elongation, length, width), and
//     where the arm enters: at the image border directly, or through a depth-continuous body (off
//     the planes) that reaches the border from one end of the arm, or - for a long, clearly
//     elongated arm off the table - at its end nearer the border ("free arm", as the simulator's
//     forearm that ends in mid-air);
//  4. skin of another tone at the far end (a held object) leaves the arm; the hand proper is the
//     part farthest from the entry in 3D (tip_length_m);
//  5. most confident first: a candidate inside an accepted hand's person is that person (face,
//     legs), one beside an accepted arm joins it; the person is grown from the arm's base (never
//     from the hand, which may hold an object) through depth-continuous cells off the planes,
//     within person_max_extent_m of the entry, person_max_depth_offset_m of its depth, and not
//     back towards the hand.
#include "scenewatch/foreground/hand_detector.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <utility>

#include <Eigen/Eigenvalues>
#include <opencv2/imgproc.hpp>

#include "frame_grid.h"
#include "plane_memory.h"
#include "skin_model.h"
#include "support_plane.h"

namespace scenewatch::foreground {

Status validate(const HandConfig& c) {
  if (!(c.min_hand_area_m2 > 0 && c.min_hand_area_m2 < c.max_hand_area_m2)) return invalid_argument("foreground.hands.min_area_m2: must be > 0 and below max_area_m2");
  if (!(c.depth_jump_m > 0 && c.depth_jump_m <= 0.5)) return invalid_argument("foreground.hands.depth_jump_m: must be in (0, 0.5]");
  if (!(c.border_margin_px >= 0 && c.border_margin_px <= 200)) return invalid_argument("foreground.hands.border_margin_px: must be in [0, 200]");
  if (!(c.person_max_range_m > 0)) return invalid_argument("foreground.hands.person_max_range_m: must be > 0");
  if (!(c.person_max_depth_offset_m > 0)) return invalid_argument("foreground.hands.person_max_depth_offset_m: must be > 0");
  if (!(c.skin_dilation_px >= 0 && c.skin_dilation_px <= 32)) return invalid_argument("foreground.hands.skin_dilation_px: must be in [0, 32]");
  if (!(c.person_max_extent_m > 0)) return invalid_argument("foreground.hands.person_max_extent_m: must be > 0");
  if (!(c.tip_length_m > 0 && c.tip_length_m <= 0.5)) return invalid_argument("foreground.hands.tip_length_m: must be in (0, 0.5]");
  if (!(c.tip_clearance_m >= 0)) return invalid_argument("foreground.hands.tip_clearance_m: must be >= 0");
  if (!(c.min_arm_length_m >= 0 && c.min_arm_length_m < c.max_arm_length_m)) return invalid_argument("foreground.hands.min_arm_length_m: must be >= 0 and below max_arm_length_m");
  if (!(c.min_arm_width_m >= 0)) return invalid_argument("foreground.hands.min_arm_width_m: must be >= 0");
  if (!(c.min_elongation >= 1)) return invalid_argument("foreground.hands.min_elongation: must be >= 1");
  if (!(c.free_arm_min_elongation >= c.min_elongation)) return invalid_argument("foreground.hands.free_arm_min_elongation: must be >= min_elongation");
  if (!(c.free_arm_min_length_m > 0)) return invalid_argument("foreground.hands.free_arm_min_length_m: must be > 0");
  if (!(c.support_plane_tolerance_m > 0 && c.support_plane_tolerance_m <= 0.1)) return invalid_argument("foreground.hands.support_plane_tolerance_m: must be in (0, 0.1]");
  if (!(c.grid_step >= 1 && c.grid_step <= 8)) return invalid_argument("foreground.hands.grid_step: must be in [1, 8]");
  return {};
}

namespace {

using Clock = std::chrono::steady_clock;

/// Fewest grid cells of a component worth looking at (JPEG speckle is smaller).
constexpr std::size_t kMinComponentCells = 12;
/// An end of the arm: its cells within this distance of the extreme along the principal axis.
constexpr double kEndSlabM = 0.04;
/// A free arm lying on the table is not one: at most this fraction of it near a support plane.
constexpr double kFreeArmMaxOnSupport = 0.3;
constexpr float kNearSupportM = 0.03f;
constexpr double kFreeArmMaxContact = 0.1;  ///< of its outline continuous with a support plane
/// A candidate with more than this fraction of its cells in an accepted hand's person is part of
/// that person, unless it is a clear second arm (this long and this elongated).
constexpr double kInPersonFraction = 0.3;
constexpr double kSecondArmMinLengthM = 0.3;
constexpr double kSecondArmMinElongation = 4.0;
/// At most this fraction of an arm's cells lies within the border margin.
constexpr double kMaxBorderFraction = 0.5;
/// Cells this far under the table plane are under the table; an arm has at most this fraction there.
constexpr float kBelowTableM = 0.03f;
constexpr double kMaxBelowTableFraction = 0.5;
/// Skin brighter or darker than the arm's base by more than this factor is not the same skin.
constexpr float kMaxToneRatio = 2.5f;
/// The person's pixels are at least the entry's distance from the hand, less this.
constexpr double kBodyBehindEntryM = 0.15;
/// A wall: a plane with at least this fraction of the points off the table and floor.
constexpr double kMinWallFraction = 0.12;

enum class Entry { kNone, kBorder, kBody, kFree };

struct Candidate {
  std::vector<int> cells;
  double area_m2 = 0;
  double elongation = 1, length_m = 0, width_m = 0;
  Entry entry = Entry::kNone;
  Eigen::Vector3d entry_point = Eigen::Vector3d::Zero();
  std::vector<int> base_cells;  ///< where the body is grown from
  std::vector<int> tip_cells;
  Eigen::Vector3d tip = Eigen::Vector3d::Zero();
  double score = 0;
};

}  // namespace

struct HandMemory::Planes {
  PlaneMemory tables;  ///< near-horizontal: table and floor
  PlaneMemory walls;
};

HandMemory::HandMemory() : planes_(std::make_unique<Planes>()) {}
HandMemory::~HandMemory() = default;
HandMemory::HandMemory(HandMemory&&) noexcept = default;
HandMemory& HandMemory::operator=(HandMemory&&) noexcept = default;
void HandMemory::reset() { *planes_ = Planes{}; }

std::size_t HandMemory::plane_searches() const { return planes_->tables.searches + planes_->walls.searches; }

void HandMemory::camera_moved(const Eigen::Isometry3f& T_now_prev) {
  // n . p + d = 0 for p in the previous frame; p = R^T (q - t) for q in the new one.
  for (PlaneMemory* memory : {&planes_->tables, &planes_->walls}) {
    for (SupportPlane& plane : memory->planes) {
      plane.normal = T_now_prev.linear() * plane.normal;
      plane.d -= plane.normal.dot(T_now_prev.translation());
    }
  }
}

HandDetection detect_hands(const Cloud& organized, const HandConfig& config) {
  return detect_hands(organized, config, nullptr);
}

HandDetection detect_hands(const Cloud& organized, const HandConfig& config, HandMemory* memory) {
  const auto t0 = Clock::now();
  HandDetection d;
  d.width = static_cast<int>(organized.width);
  d.height = static_cast<int>(organized.height);
  const auto finish = [&]() {
    d.ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    return d;
  };
  if (!config.enabled || !validate(config).ok()) return finish();
  if (organized.height < 2 || organized.width < 2 ||
      organized.points.size() != static_cast<std::size_t>(organized.width) * organized.height) {
    return finish();
  }
  const std::size_t full_n = organized.points.size();
  d.labels.assign(full_n, AgentLabel::kNone);

  const Grid g = sample_grid(organized, config.grid_step);
  const std::size_t n = g.p.size();
  std::size_t valid_count = 0;
  for (auto v : g.valid) valid_count += v;
  if (valid_count < kMinComponentCells) return finish();
  const double focal = estimate_focal_px(g);
  const float jump = static_cast<float>(config.depth_jump_m);
  const int margin = config.border_margin_px;

  // 1. Skin. Closing bridges one-cell gaps in the mask: a dark forearm in shadow breaks into pieces
  // where single pixels fall below the luminance gate. Dilating then tolerates colour and depth
  // that are not quite registered (hrt1's are ~15 px apart at the image's side): the skin's
  // depth lies beside its colour. The components are depth-continuous, so the dilated mask does
  // not join the background.
  std::vector<std::uint8_t> skin = skin_mask(g.rgb, g.w, g.h);
  const std::vector<std::uint8_t> skin_colour = skin;  // before closing and dilation
  const int dilation_radius = (config.skin_dilation_px + g.step - 1) / g.step;
  {
    cv::Mat mask(g.h, g.w, CV_8U, skin.data());
    cv::morphologyEx(mask, mask, cv::MORPH_CLOSE, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3)));
    if (dilation_radius > 0) {
      cv::dilate(mask, mask, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * dilation_radius + 1, 2 * dilation_radius + 1)));
    }
  }
  std::vector<float> luma(n);  // BT.601 luminance, +1 so that ratios stay finite
  for (std::size_t c = 0; c < n; ++c) luma[c] = 0.299f * g.rgb[3 * c] + 0.587f * g.rgb[3 * c + 1] + 0.114f * g.rgb[3 * c + 2] + 1.0f;

  // Planes.
  SupportPlaneConfig plane_config;
  plane_config.tolerance_m = static_cast<float>(config.support_plane_tolerance_m);
  // Planes are found on a coarser grid (every other cell; they are large, and RANSAC's cost is
  // in the points), then a cell lies on one when its coarse cell is in a kept patch and the cell
  // itself is within the tolerance.
  const int cw = (g.w + 1) / 2, ch = (g.h + 1) / 2;
  std::vector<Eigen::Vector3f> coarse_p(static_cast<std::size_t>(cw) * ch);
  std::vector<std::uint8_t> coarse_valid(coarse_p.size(), 0);
  for (int v = 0; v < ch; ++v) {
    for (int u = 0; u < cw; ++u) {
      const std::size_t fine = static_cast<std::size_t>(2 * v) * g.w + 2 * u;
      coarse_p[static_cast<std::size_t>(v) * cw + u] = g.p[fine];
      coarse_valid[static_cast<std::size_t>(v) * cw + u] = g.valid[fine];
    }
  }
  std::vector<std::uint8_t> coarse_table, coarse_wall;
  const std::vector<SupportPlane> planes = find_support_planes(coarse_p, coarse_valid, cw, ch, plane_config, &coarse_table,
                                                                  memory ? &memory->planes().tables : nullptr);
  // Then walls: any plane covering a good part of what is left. A person's body is never that
  // large and flat; without this the body grows into a wall it stands close to.
  std::vector<std::uint8_t> rest(coarse_p.size(), 0);
  for (std::size_t c = 0; c < rest.size(); ++c) rest[c] = coarse_valid[c] && !coarse_table[c];
  SupportPlaneConfig wall_config = plane_config;
  wall_config.min_abs_normal_y = 0.0f;
  wall_config.min_fraction = kMinWallFraction;
  const std::vector<SupportPlane> walls = find_support_planes(coarse_p, rest, cw, ch, wall_config, &coarse_wall,
                                                                 memory ? &memory->planes().walls : nullptr);
  // Distance to the table or floor, for telling an arm held up from an object lying there.
  std::vector<float> plane_distance(n, std::numeric_limits<float>::infinity());
  cv::Mat on_support(g.h, g.w, CV_8U, cv::Scalar(0));
  for (int gv = 0; gv < g.h; ++gv) {
    for (int gu = 0; gu < g.w; ++gu) {
      const std::size_t c = static_cast<std::size_t>(gv) * g.w + gu;
      if (!g.valid[c]) continue;
      for (const SupportPlane& plane : planes) plane_distance[c] = std::min(plane_distance[c], std::abs(plane.distance(g.p[c])));
      const std::size_t coarse = static_cast<std::size_t>(gv / 2) * cw + gu / 2;
      const float tolerance = plane_config.tolerance_at(g.p[c].z());
      bool on = coarse_table[coarse] && plane_distance[c] < tolerance;
      if (!on && coarse_wall[coarse]) {
        for (const SupportPlane& wall : walls) on |= std::abs(wall.distance(g.p[c])) < tolerance;
      }
      on_support.data[c] = on;
    }
  }
  // The person may not enter a band around the planes either: the table's rounded edge is off
  // the plane but part of the table.
  cv::Mat near_support;
  cv::dilate(on_support, near_support, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(5, 5)));

  // 2. Skin components.
  std::vector<int> component(n, 0);
  std::vector<std::vector<int>> components;
  for (std::size_t c = 0; c < n; ++c) {
    if (component[c] != 0 || !g.valid[c] || !skin[c] || on_support.data[c]) continue;
    const int id = static_cast<int>(components.size()) + 1;
    components.push_back(grow(g, {static_cast<int>(c)}, jump, component, id,
                              [&](int i) { return skin[i] && !on_support.data[i]; }));
  }

  // 3-4. Which components are arms with a hand, where they enter and where their hand is.
  const double cell_side = g.step / focal;  // metres per metre of depth
  std::vector<Candidate> candidates;
  std::vector<int> scratch(n, 0);
  int scratch_id = 0;
  for (const std::vector<int>& cells : components) {
    if (cells.size() < kMinComponentCells) continue;
    Candidate cand;
    cand.cells = cells;
    for (int i : cells) cand.area_m2 += std::pow(g.p[i].z() * cell_side, 2);
    if (cand.area_m2 < config.min_hand_area_m2 || cand.area_m2 > config.max_hand_area_m2) continue;

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
    if (cand.width_m < config.min_arm_width_m) continue;
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
      continue;
    }

    // Legs (bare, or trousers of a skin-like colour) are under the table; a hand working on it
    // is above its plane. planes[0] is the largest horizontal plane; its normal points towards
    // the camera, which looks down on it.
    if (!planes.empty()) {
      std::size_t below = 0;
      for (int i : cells) below += planes[0].distance(g.p[i]) < -kBelowTableM;
      if (below > kMaxBelowTableFraction * cells.size()) continue;
    }
    std::vector<int> border;
    for (int i : cells) {
      if (g.on_border(i, margin)) border.push_back(i);
    }
    // An arm crosses the border; a strip along it (a bright edge of the ceiling) lies on it.
    if (border.size() > kMaxBorderFraction * cells.size()) continue;
    if (border.size() >= 2) {
      cand.entry = Entry::kBorder;
      cand.entry_point = centroid_of(g, border);
    } else {
      // Through a body: grow from each end of the arm over depth-continuous pixels off the support
      // planes; the end whose growth reaches the border is where the arm enters.
      std::vector<int> ends[2];
      for (std::size_t k = 0; k < cells.size(); ++k) {
        if (t[k] <= t_min + kEndSlabM) ends[0].push_back(cells[k]);
        if (t[k] >= t_max - kEndSlabM) ends[1].push_back(cells[k]);
      }
      // When both ends reach the border (one through a held object and a table edge), the arm
      // enters at the end nearer the border: arms come from outside the view.
      double best_border_distance = std::numeric_limits<double>::infinity();
      for (int e = 0; e < 2; ++e) {
        const Eigen::Vector3d end_point = centroid_of(g, ends[e]);
        const int id = ++scratch_id;
        bool reaches = false;
        const std::vector<int> body = grow(g, ends[e], jump, scratch, id, [&](int i) {
          // Not through skin: a skin-coloured part of a held object would otherwise reach the
          // border through the hand and arm that hold it.
          if (component[i] != 0 || skin[i] || near_support.data[i]) return false;
          if (g.p[i].z() > config.person_max_range_m) return false;
          if ((g.p[i].cast<double>() - end_point).norm() > config.person_max_extent_m) return false;
          if (g.on_border(i, margin)) reaches = true;
          return true;
        });
        const double border_distance = distance_to_border(g, ends[e]);
        if (reaches && border_distance < best_border_distance) {
          best_border_distance = border_distance;
          cand.entry = Entry::kBody;
          cand.entry_point = end_point;
        }
      }
      if (cand.entry == Entry::kNone && cand.elongation >= config.free_arm_min_elongation &&
          cand.length_m >= config.free_arm_min_length_m) {
        // Lying on the table: much of it near the plane, or its outline continuous in depth with
        // the plane (an object's foot). A held-up arm is separated from the table by a depth jump.
        std::size_t near = 0, outline = 0, contact = 0;
        const int own = component[cells.front()];
        for (int i : cells) {
          near += plane_distance[i] < kNearSupportM;
          const int cu = i % g.w, cv = i / g.w;
          bool on_outline = false, touches = false;
          for (const auto& [du, dv] : {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}}) {
            const int nu = cu + du, nv = cv + dv;
            if (nu < 0 || nv < 0 || nu >= g.w || nv >= g.h) continue;
            const int nb = nv * g.w + nu;
            if (component[nb] == own) continue;
            on_outline = true;
            touches |= g.valid[nb] && on_support.data[nb] && std::abs(g.p[nb].z() - g.p[i].z()) < jump;
          }
          outline += on_outline;
          contact += touches;
        }
        if (near <= kFreeArmMaxOnSupport * cells.size() && contact <= kFreeArmMaxContact * outline) {
          // No body in view: the arm comes from outside the image, so it enters at its end nearer
          // the border.
          cand.entry = Entry::kFree;
          cand.entry_point = centroid_of(g, ends[distance_to_border(g, ends[0]) <= distance_to_border(g, ends[1]) ? 0 : 1]);
        }
      }
    }
    if (cand.entry == Entry::kNone) continue;

    std::vector<double> reach(cand.cells.size());
    double reach_max = 0;
    for (std::size_t k = 0; k < cand.cells.size(); ++k) {
      reach[k] = (g.p[cand.cells[k]].cast<double>() - cand.entry_point).norm();
      reach_max = std::max(reach_max, reach[k]);
    }
    // Skin of another tone in the far half is what the hand holds (a plush toy's light face in
    // dark fingers, touching them in colour and depth): it leaves the arm, with the dilated
    // rim around it, before the hand proper is measured.
    {
      std::vector<float> base;
      for (std::size_t k = 0; k < cand.cells.size(); ++k) {
        if (skin_colour[cand.cells[k]] && reach[k] < 0.5 * reach_max) base.push_back(luma[cand.cells[k]]);
      }
      if (base.size() >= kMinComponentCells) {
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
        if (any) {
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
      }
    }
    if (cand.cells.size() < kMinComponentCells) continue;
    for (std::size_t k = 0; k < cand.cells.size(); ++k) {
      if (reach[k] >= reach_max - config.tip_length_m) cand.tip_cells.push_back(cand.cells[k]);
      // The body is grown from the arm's base only, well away from the hand and what it holds.
      if (reach[k] < reach_max - config.tip_length_m - config.tip_clearance_m) cand.base_cells.push_back(cand.cells[k]);
    }
    if (cand.base_cells.empty()) {
      for (std::size_t k = 0; k < cand.cells.size(); ++k) {
        if (reach[k] < reach_max - config.tip_length_m) cand.base_cells.push_back(cand.cells[k]);
      }
    }
    cand.tip = centroid_of(g, cand.tip_cells);

    // Score: how it enters (the border is the strongest evidence, a free arm the weakest), how
    // arm-like and how long it is (a hand with forearm is 0.3-0.5 m; a patch of skin-coloured
    // trousers or a face 0.1-0.25 m).
    const double entry_score = cand.entry == Entry::kBorder ? 1.0 : cand.entry == Entry::kBody ? 0.9 : 0.6;
    const double elongation_score = std::clamp((cand.elongation - 1.0) / 4.0, 0.0, 1.0);
    const double length_score = std::clamp((cand.length_m - 0.1) / 0.3, 0.0, 1.0);
    cand.score = std::clamp(entry_score * (0.4 + 0.2 * elongation_score + 0.4 * length_score), 0.0, 1.0);
    candidates.push_back(std::move(cand));
  }
  std::stable_sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) { return a.score > b.score; });

  // 5. Most confident first: accept a hand, grow its person. A later candidate inside that person
  // (a face, skin-coloured trousers) is the person, unless it is clearly a second arm; one next to
  // an accepted hand (a skin-coloured part of what it holds) is nothing.
  std::vector<AgentLabel> grid_label(n, AgentLabel::kNone);
  std::vector<int> owner(n, -1);
  std::vector<Candidate> accepted;
  for (Candidate& cand : candidates) {
    std::size_t in_person = 0;
    for (int i : cand.cells) in_person += grid_label[i] == AgentLabel::kPerson;
    const bool second_arm = cand.length_m >= kSecondArmMinLengthM && cand.elongation >= kSecondArmMinElongation;
    if (in_person > kInPersonFraction * cand.cells.size() && !second_arm) {
      for (int i : cand.cells) grid_label[i] = AgentLabel::kPerson;
      continue;
    }
    bool at_a_hand = false;
    for (const Candidate& hand : accepted) {
      if ((cand.tip - hand.tip).norm() < config.tip_clearance_m + config.tip_length_m) at_a_hand = true;
    }
    if (at_a_hand) continue;
    // A piece beside an accepted arm is more of that arm (split off by a depth jump along a
    // silhouette, or by colour and depth that do not quite line up).
    int touching = -1;
    for (int i : cand.cells) {
      const int cu = i % g.w, cv = i / g.w;
      for (const auto& [du, dv] : {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}}) {
        const int nu = cu + du, nv = cv + dv;
        if (nu < 0 || nv < 0 || nu >= g.w || nv >= g.h) continue;
        if (owner[nv * g.w + nu] >= 0) touching = owner[nv * g.w + nu];
      }
      if (touching >= 0) break;
    }
    if (touching >= 0) {
      for (int i : cand.cells) {
        if (grid_label[i] == AgentLabel::kNone) grid_label[i] = AgentLabel::kArm, owner[i] = touching;
      }
      continue;
    }
    const int index = static_cast<int>(accepted.size());
    for (int i : cand.cells) grid_label[i] = AgentLabel::kArm, owner[i] = index;
    for (int i : cand.tip_cells) grid_label[i] = AgentLabel::kHand;
    const double min_tip_distance = std::max(config.tip_clearance_m, (cand.entry_point - cand.tip).norm() - kBodyBehindEntryM);
    // The seeds (arm cells) come back in the growth; only unlabelled cells become the person.
    // Cells of other skin components may join: a face or bare legs are the person's.
    const std::vector<int> body = grow(g, cand.base_cells, jump, scratch, ++scratch_id, [&](int i) {
      if (grid_label[i] == AgentLabel::kHand || grid_label[i] == AgentLabel::kArm || near_support.data[i]) return false;
      // Nor onto the table's plane beyond the patches found: where the plane fit missed part of
      // the table (a missed body pixel is better than the table as a person).
      if (plane_distance[i] < plane_config.tolerance_at(g.p[i].z())) return false;
      if (g.p[i].z() > config.person_max_range_m) return false;
      // Depth edges are smeared (mixed pixels ramp from the body to the wall behind it): the
      // body stays within this depth of the arm's entry.
      if (std::abs(g.p[i].z() - cand.entry_point.z()) > config.person_max_depth_offset_m) return false;
      const Eigen::Vector3d q = g.p[i].cast<double>();
      if ((q - cand.entry_point).norm() > config.person_max_extent_m) return false;
      // The body lies beyond the arm's entry as seen from the hand: not back towards the hand
      // along a wall or a table edge.
      for (const Candidate& hand : accepted) {
        if ((q - hand.tip).norm() < config.tip_clearance_m) return false;
      }
      return (q - cand.tip).norm() >= min_tip_distance;
    });
    for (int i : body) {
      if (grid_label[i] == AgentLabel::kNone) grid_label[i] = AgentLabel::kPerson;
    }
    accepted.push_back(std::move(cand));
  }

  // Upsample: a full-resolution pixel takes its grid cell's label when its depth is continuous
  // with the cell's sample.
  d.hands.resize(accepted.size());
  for (int gv = 0; gv < g.h; ++gv) {
    for (int gu = 0; gu < g.w; ++gu) {
      const int cell = gv * g.w + gu;
      const AgentLabel label = grid_label[cell];
      if (label == AgentLabel::kNone) continue;
      const float z = g.p[cell].z();
      for (int v = gv * g.step; v < std::min(g.full_h, (gv + 1) * g.step); ++v) {
        for (int u = gu * g.step; u < std::min(g.full_w, (gu + 1) * g.step); ++u) {
          const int i = v * g.full_w + u;
          const PointT& pt = organized.points[i];
          if (!is_valid(pt) || std::abs(pt.z - z) >= jump) continue;
          d.labels[i] = label;
          if (label == AgentLabel::kPerson) {
            d.person_indices.push_back(i);
          } else {
            Hand& hand = d.hands[owner[cell]];
            hand.indices.push_back(i);
            if (label == AgentLabel::kHand) hand.tip_indices.push_back(i);
          }
        }
      }
    }
  }
  std::sort(d.person_indices.begin(), d.person_indices.end());
  for (std::size_t h = 0; h < accepted.size(); ++h) {
    Hand& hand = d.hands[h];
    const Candidate& cand = accepted[h];
    std::sort(hand.indices.begin(), hand.indices.end());
    std::sort(hand.tip_indices.begin(), hand.tip_indices.end());
    int u0 = d.width, v0 = d.height, u1 = -1, v1 = -1;
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (int i : hand.indices) {
      const int u = i % d.width, v = i / d.width;
      u0 = std::min(u0, u), v0 = std::min(v0, v), u1 = std::max(u1, u), v1 = std::max(v1, v);
      const Eigen::Vector3d q = organized.points[i].getVector3fMap().cast<double>();
      lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
    }
    if (!hand.indices.empty()) {
      hand.region = PixelRegion{u0, v0, u1 - u0 + 1, v1 - v0 + 1, static_cast<std::uint32_t>(hand.indices.size())};
      hand.box_camera.min = lo;
      hand.box_camera.max = hi;
    }
    Eigen::Vector3d tip = Eigen::Vector3d::Zero();
    for (int i : hand.tip_indices) tip += organized.points[i].getVector3fMap().cast<double>();
    hand.tip_camera = hand.tip_indices.empty() ? cand.tip : Eigen::Vector3d(tip / static_cast<double>(hand.tip_indices.size()));
    hand.enters_from_border = cand.entry == Entry::kBorder || cand.entry == Entry::kBody;
    hand.score = cand.score;
    hand.area_m2 = cand.area_m2;
    hand.elongation = cand.elongation;
    hand.length_m = cand.length_m;
    hand.width_m = cand.width_m;
  }
  return finish();
}

}  // namespace scenewatch::foreground
