#pragma once
/// Steps 2-4 of the hand detector (hand_detector.cpp): the skin components off the planes, which
/// of them are arms, where each enters the view and where its hand is. Private to the foreground
/// module.
#include <vector>

#include <Eigen/Core>

#include "frame_grid.h"
#include "scenewatch/foreground/hand_detector.h"
#include "skin_cells.h"
#include "support_cells.h"

namespace scenewatch::foreground {

/// Fewest grid cells of a component worth looking at (JPEG speckle is smaller).
constexpr std::size_t kMinComponentCells = 12;

/// Where an arm enters: at the image border, through a body that reaches it, or - a long arm
/// with no body in view - at its end nearer the border.
enum class Entry { kNone, kBorder, kBody, kFree };

/// An arm that may carry a hand, in grid cells.
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

/// The arms among the skin components off the planes, the most confident first (stable order).
std::vector<Candidate> find_hand_candidates(const Grid& g, const SkinCells& skin, const SupportCells& supports,
                                            const HandConfig& config);

}  // namespace scenewatch::foreground
