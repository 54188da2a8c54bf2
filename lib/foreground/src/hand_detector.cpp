// Hands, arms and the person in an organized RGB-D frame: the steps in order, each in its own file.
//
// Steps, on a grid of every grid_step-th pixel (frame_grid.h; labels are upsampled at the end):
//  1. skin mask (skin_model.h), closed and dilated (skin_cells.h); large planes (support_plane.h):
//     table and floor (near-horizontal), then walls (support_cells.h);
//  2. connected components of skin cells off those planes, neighbours joined only when their
//     depths differ by less than depth_jump_m (hand_candidates.h, as 3 and 4);
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
//     back towards the hand (hand_acceptance.h);
//  then the grid's labels are carried to full resolution (label_upsampling.h) and each hand's
//  figures are taken from its full-resolution pixels (here).
#include "scenewatch/foreground/hand_detector.h"

#include <algorithm>
#include <chrono>
#include <limits>
#include <utility>

#include "frame_grid.h"
#include "hand_acceptance.h"
#include "hand_candidates.h"
#include "label_upsampling.h"
#include "plane_memory.h"
#include "skin_cells.h"
#include "support_cells.h"

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

// An accepted hand's figures: its pixel region and camera-frame box from its full-resolution
// pixels, its tip from theirs, and the candidate's shape and score.
void describe_hand(const Cloud& organized, const Candidate& cand, int width, int height, Hand& hand) {
  int u0 = width, v0 = height, u1 = -1, v1 = -1;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (int i : hand.indices) {
    const int u = i % width, v = i / width;
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
  std::size_t valid_count = 0;
  for (auto v : g.valid) valid_count += v;
  if (valid_count < kMinComponentCells) return finish();

  const SkinCells skin = find_skin_cells(g, config.skin_dilation_px);                       // 1.
  const SupportCells supports = find_support_cells(g, static_cast<float>(config.support_plane_tolerance_m),
                                                   memory ? &memory->planes().tables : nullptr,
                                                   memory ? &memory->planes().walls : nullptr);
  std::vector<Candidate> candidates = find_hand_candidates(g, skin, supports, config);      // 2-4.
  const AcceptedHands accepted = accept_hands(g, std::move(candidates), supports, config);  // 5.
  upsample_labels(organized, g, accepted, static_cast<float>(config.depth_jump_m), d);
  for (std::size_t h = 0; h < accepted.hands.size(); ++h) describe_hand(organized, accepted.hands[h], d.width, d.height, d.hands[h]);
  return finish();
}

}  // namespace scenewatch::foreground
