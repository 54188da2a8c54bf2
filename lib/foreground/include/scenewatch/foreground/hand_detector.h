#pragma once
/// Hands and people in an RGB-D frame (issue 12, part 1).
///
/// A hand is skin-coloured (a skin model in a colour space robust to lighting), forms a connected
/// component with continuous depth, has a plausible size, and belongs to an arm that enters from
/// the image border; a skin-coloured object lying on the table is not a hand. The rest of a person
/// in view (body, head) is a dynamic agent: neither a background change nor an object, and never
/// written into the background map.
#include <cstdint>
#include <memory>
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
  double person_max_extent_m = 1.2;  ///< ... and no farther than this from where the arm enters
  double person_max_depth_offset_m = 0.5;  ///< ... nor farther than this in depth from that entry
  int skin_dilation_px = 4;          ///< the skin mask grown by this: colour and depth slightly misregistered
  double tip_length_m = 0.12;        ///< the hand proper: this much of the arm's far end, in 3D
  double tip_clearance_m = 0.15;     ///< the body is not grown this close to the hand (a held object)
  double min_arm_length_m = 0.15;    ///< a hand with some forearm is at least this long
  double max_arm_length_m = 0.9;     ///< a whole arm, shoulder to fingertips, is about 0.75 m
  double min_arm_width_m = 0.05;     ///< a forearm is 6-9 cm wide; a board's edge or a slat is thinner
  double min_elongation = 3.0;       ///< an arm's length over its width (principal axes), at least
  /// An arm that reaches neither the border nor a body that does (a cut-off view, the simulator's
  /// floating forearm) is still a hand when this elongated, this long, and not lying on the table.
  double free_arm_min_elongation = 4.0;
  double free_arm_min_length_m = 0.25;
  double support_plane_tolerance_m = 0.015;  ///< points this close to the table or floor plane are on it
  int grid_step = 2;                 ///< work on every grid_step-th pixel per axis, labels upsampled
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
  bool enters_from_border = false;   ///< directly, or through a body that reaches the border
  double score = 0.0;                ///< in [0, 1]: how sure
  double area_m2 = 0.0;              ///< metric area of hand and forearm, from depth
  double elongation = 0.0;           ///< length over width (square root of the principal variances' ratio)
  double length_m = 0.0;             ///< extent along the principal axis
  double width_m = 0.0;              ///< sqrt(12) times the spread across it (a uniform strip's width)
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
/// one without colour, gives an empty detection (not an error). A hand needs some forearm (it is
/// told from skin-coloured things by its arm's shape); skin-coloured wood that is as long and
/// wide as a forearm and cut by the border is a known source of false hands. Stateless: safe to
/// call from several threads at once.
HandDetection detect_hands(const Cloud& organized, const HandConfig& config);

/// What the detector keeps between the frames of one stream: the table, floor and walls it found,
/// which it checks cheaply on the next frames instead of searching for them again while they still
/// explain the frame (a fixed camera's table does not move). NOT thread safe: one per stream.
class HandMemory {
 public:
  HandMemory();
  ~HandMemory();
  HandMemory(HandMemory&&) noexcept;
  HandMemory& operator=(HandMemory&&) noexcept;
  /// Forgets the planes (a new stream).
  void reset();
  /// The camera moved by `T_now_prev` (a point in the previous frame's camera coordinates to the
  /// new one's): the remembered planes are moved with it, to be checked on the next frame as
  /// usual (a plane that no longer holds is searched for again).
  void camera_moved(const Eigen::Isometry3f& T_now_prev);
  /// How many times the planes were searched for (RANSAC) since the memory was made or reset.
  std::size_t plane_searches() const;
  struct Planes;  ///< private to the detector
  Planes& planes() { return *planes_; }

 private:
  std::unique_ptr<Planes> planes_;
};

/// detect_hands for a stream of frames: the same detection, with the support planes taken from
/// `memory` while they hold (memory == nullptr: as detect_hands above).
HandDetection detect_hands(const Cloud& organized, const HandConfig& config, HandMemory* memory);

}  // namespace scenewatch::foreground
