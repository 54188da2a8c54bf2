#pragma once
/// Hands and people in an RGB-D frame (issue 12, part 1).
///
/// A hand is skin-coloured (a skin model in a colour space robust to lighting), forms a connected
/// component with continuous depth, has a plausible size, and belongs to an arm that enters from
/// the image border; a skin-coloured object lying on the table is not a hand. The rest of a person
/// in view (body, head) is a dynamic agent: neither a background change nor an object, and never
/// written into the background map.
#include <cstdint>
#include <vector>

#include "scenewatch/core/cloud.h"
#include "scenewatch/core/event.h"
#include "scenewatch/core/geometry.h"
#include "scenewatch/core/result.h"

namespace scenewatch::foreground {

struct HandConfig {
  bool enabled = true;
  double min_hand_area_m2 = 0.002;   ///< smaller skin regions are not a hand (metric, from depth)
  double max_hand_area_m2 = 0.25;    ///< larger are not a hand (a wall, a wooden table)
  double depth_jump_m = 0.03;        ///< neighbours farther apart in depth are not connected
  int border_margin_px = 12;         ///< an arm "enters from the border" within this margin
  double person_max_range_m = 4.0;   ///< the person's body is grown from the arm up to this range
};

/// What a pixel of the frame is.
enum class AgentLabel : std::uint8_t { kNone = 0, kHand = 1, kArm = 2, kPerson = 3 };

/// One hand with its forearm (one connected skin component that passed the checks).
struct Hand {
  std::vector<int> indices;          ///< pixels (row-major indices into the organized cloud): hand and forearm
  std::vector<int> tip_indices;      ///< the part farthest from where the arm enters: the hand proper
  PixelRegion region;                ///< bounding rectangle of all its pixels
  Aabb box_camera;                   ///< of its 3D points, camera frame
  Eigen::Vector3d tip_camera = Eigen::Vector3d::Zero();  ///< centroid of the hand proper, camera frame
  bool enters_from_border = false;
  double score = 0.0;                ///< in [0, 1]: how sure
};

struct HandDetection {
  int width = 0, height = 0;
  std::vector<AgentLabel> labels;    ///< width * height; kNone where no agent
  std::vector<Hand> hands;           ///< most confident first
  std::vector<int> person_indices;   ///< body/head pixels grown from the arms (not hand, not arm)
  double ms = 0.0;
  /// Pixels of any agent (hand, arm or person): what must stay out of the map and of the objects.
  bool is_agent(int index) const { return !labels.empty() && labels[static_cast<std::size_t>(index)] != AgentLabel::kNone; }
};

Status validate(const HandConfig& config);

/// Hands, arms and the person in an organized RGB cloud (camera frame). An unorganized cloud, or
/// one without colour, gives an empty detection (not an error).
HandDetection detect_hands(const Cloud& organized, const HandConfig& config);

}  // namespace scenewatch::foreground
