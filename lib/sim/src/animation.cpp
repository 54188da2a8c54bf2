#include "scenewatch/sim/animation.h"

#include <algorithm>
#include <limits>
#include <string>

namespace scenewatch::sim {

Result<Animator> Animator::create(std::vector<SceneObject> objects, HandSpec hand, double touch_tolerance_m) {
  Animator a;
  a.objects_ = std::move(objects);
  a.hand_ = std::move(hand);
  a.touch_tolerance_m_ = touch_tolerance_m;
  if (!a.hand_.keys.empty()) a.parts_ = sim::hand_parts(a.hand_.scale);
  for (std::size_t k = 1; k < a.hand_.keys.size(); ++k) {
    if (a.hand_.keys[k].frame < a.hand_.keys[k - 1].frame) {
      return invalid_argument("hand.keys[" + std::to_string(k) + "].frame: keys must be in time order");
    }
  }
  auto index_of = [&](int id) -> std::optional<std::size_t> {
    for (std::size_t i = 0; i < a.objects_.size(); ++i) {
      if (a.objects_[i].id == id) return i;
    }
    return std::nullopt;
  };
  std::optional<std::size_t> open;  // index into attachments_ of the object now in the hand
  for (std::size_t k = 0; k < a.hand_.keys.size(); ++k) {
    const HandKey& key = a.hand_.keys[k];
    const std::string where = "hand.keys[" + std::to_string(k) + "]";
    if (key.release_id > 0) {
      if (!open || a.objects_[a.attachments_[*open].object].id != key.release_id) {
        return invalid_argument(where + ".release: object " + std::to_string(key.release_id) + " is not in the hand");
      }
      a.attachments_[*open].release_frame = key.frame;
      open.reset();
    }
    if (key.grasp_id > 0) {
      const auto idx = index_of(key.grasp_id);
      if (!idx) return invalid_argument(where + ".grasp: no object with id " + std::to_string(key.grasp_id) + " in this phase");
      if (open) return invalid_argument(where + ".grasp: the hand already holds object " +
                                        std::to_string(a.objects_[a.attachments_[*open].object].id));
      Attachment att;
      att.object = *idx;
      att.grasp_frame = key.frame;
      att.release_frame = std::numeric_limits<double>::infinity();
      att.T_hand_object = hand_pose(a.hand_, key.frame).inverse() * a.object_pose(*idx, key.frame);
      a.attachments_.push_back(att);
      open = a.attachments_.size() - 1;
    }
  }
  return a;
}

Pose Animator::object_pose(std::size_t index, double frame) const {
  Pose T = objects_[index].T_world_object;
  for (const Attachment& att : attachments_) {
    if (att.object != index) continue;
    if (frame < att.grasp_frame) return T;
    if (frame <= att.release_frame) return hand_pose(hand_, frame) * att.T_hand_object;
    T = hand_pose(hand_, att.release_frame) * att.T_hand_object;
  }
  return T;
}

WorldState Animator::state_at(double frame) const {
  WorldState s;
  s.T_world_object.reserve(objects_.size());
  for (std::size_t i = 0; i < objects_.size(); ++i) s.T_world_object.push_back(object_pose(i, frame));
  if (hand_.keys.empty()) return s;
  const Pose T_world_hand = hand_pose(hand_, frame);
  s.T_world_hand = T_world_hand;
  for (const Attachment& att : attachments_) {
    if (frame >= att.grasp_frame && frame < att.release_frame) s.held.push_back(objects_[att.object].id);
  }
  for (std::size_t i = 0; i < objects_.size(); ++i) {
    const int id = objects_[i].id;
    bool touched = std::find(s.held.begin(), s.held.end(), id) != s.held.end();
    const Pose T_object_hand = s.T_world_object[i].inverse() * T_world_hand;
    for (std::size_t p = 0; p < parts_.size() && !touched; ++p) {
      // Sample the capsule's axis; a touch is an axis point within radius + tolerance of the surface.
      const HandPart& part = parts_[p];
      const double r = part.shape.radius_m;
      const Pose T_object_part = T_object_hand * part.T_hand_part;
      constexpr int kSamples = 6;
      for (int k = 0; k <= kSamples && !touched; ++k) {
        const Eigen::Vector3d axis_point(0, 0, r + part.shape.height_m * k / kSamples);
        if (signed_distance(objects_[i].shape, T_object_part * axis_point) <= r + touch_tolerance_m_) touched = true;
      }
    }
    if (touched) s.touched.push_back(id);
  }
  return s;
}

}  // namespace scenewatch::sim
