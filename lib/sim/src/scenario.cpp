#include "scenewatch/sim/scenario.h"

#include <cmath>
#include <set>
#include <string>

namespace scenewatch::sim {
namespace {

Status check_shape(const Shape& s, const std::string& where) {
  auto positive = [&](double v, const char* key) -> Status {
    if (!(v > 0.0) || !std::isfinite(v)) return invalid_argument(where + "." + key + ": must be positive");
    return {};
  };
  switch (s.kind) {
    case ShapeKind::kBox:
      for (int i = 0; i < 3; ++i) {
        if (!(s.size_m[i] > 0.0)) return invalid_argument(where + ".size_m: sides must be positive");
      }
      return {};
    case ShapeKind::kCylinder:
    case ShapeKind::kFrustum: {
      if (auto st = positive(s.height_m, "height_m"); !st) return st;
      if (auto st = positive(s.radius_m, "radius_m"); !st) return st;
      if (s.kind == ShapeKind::kFrustum && !(s.top_radius_m >= 0.0)) {
        return invalid_argument(where + ".top_radius_m: must not be negative");
      }
      if (s.open_top) {
        const double r_min = std::min(s.radius_m, s.top_radius_or_radius_m());
        if (!(s.wall_m > 0.0) || s.wall_m >= r_min || s.wall_m >= s.height_m) {
          return invalid_argument(where + ".wall_m: must be positive and smaller than the radii and the height");
        }
      }
      return {};
    }
    case ShapeKind::kSphere:
      return positive(s.radius_m, "radius_m");
    case ShapeKind::kCapsule:
      if (auto st = positive(s.radius_m, "radius_m"); !st) return st;
      return positive(s.height_m, "height_m");
  }
  return {};
}

}  // namespace

TableSpec::TableSpec() {
  top.color = Eigen::Vector3d(178, 128, 82);
  top.color2 = Eigen::Vector3d(128, 84, 48);
  top.texture = TextureKind::kWood;
  top.scale_m = 0.08;
  legs.color = Eigen::Vector3d(70, 60, 55);
}

Pose TableSpec::T_world_support() const {
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(yaw_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(center_world.x(), center_world.y(), height_m);
  return T;
}

Scenario::Scenario() {
  room.floor.color = Eigen::Vector3d(150, 150, 145);
  room.floor.color2 = Eigen::Vector3d(110, 110, 108);
  room.floor.texture = TextureKind::kChecker;
  room.floor.scale_m = 0.4;
  room.walls.color = Eigen::Vector3d(225, 222, 210);
  room.ceiling.color = Eigen::Vector3d(240, 240, 240);
}

Status validate(const Scenario& sc) {
  if (!sc.intrinsics.valid()) return invalid_argument("intrinsics: fx, fy, width and height must be positive");
  if (!(sc.frame_rate_hz > 0)) return invalid_argument("frame_rate_hz: must be positive");
  if (sc.phases.empty()) return invalid_argument("phases: a scenario needs at least one phase");
  if ((sc.room.max_world - sc.room.min_world).minCoeff() <= 0) return invalid_argument("room: empty room");
  if (sc.table.present) {
    if (sc.table.size_m.minCoeff() <= 0 || sc.table.height_m <= sc.table.thickness_m || sc.table.thickness_m <= 0) {
      return invalid_argument("table: size_m, height_m and thickness_m must be positive, the height above the thickness");
    }
  }
  // Ids are checked phase by phase, as changes add and remove objects.
  std::set<int> ids;
  auto check_object = [&](const SceneObject& o, const std::string& where) -> Status {
    if (o.id < 1 || o.id > kMaxObjectId) {
      return invalid_argument(where + ".id: must be in 1.." + std::to_string(kMaxObjectId) + " (label = id * 10)");
    }
    if (!ids.insert(o.id).second) return invalid_argument(where + ".id: duplicate object id " + std::to_string(o.id));
    return check_shape(o.shape, where);
  };
  for (std::size_t i = 0; i < sc.objects.size(); ++i) {
    if (auto st = check_object(sc.objects[i], "objects[" + std::to_string(i) + "]"); !st) return st;
  }
  for (std::size_t p = 0; p < sc.phases.size(); ++p) {
    const PhaseSpec& ph = sc.phases[p];
    const std::string where = "phases[" + std::to_string(p) + "]";
    if (ph.frames < 1) return invalid_argument(where + ".frames: must be at least 1");
    const SceneChanges& ch = ph.changes;
    if (p == 0 && (!ch.remove.empty() || !ch.add.empty() || !ch.move.empty())) {
      return invalid_argument(where + ".changes: the first phase cannot change the scene (describe it in objects)");
    }
    for (int id : ch.remove) {
      if (!ids.erase(id)) return invalid_argument(where + ".changes.remove: no object with id " + std::to_string(id));
    }
    for (const ObjectMove& m : ch.move) {
      if (!ids.count(m.id)) return invalid_argument(where + ".changes.move: no object with id " + std::to_string(m.id));
    }
    for (std::size_t i = 0; i < ch.add.size(); ++i) {
      if (auto st = check_object(ch.add[i], where + ".changes.add[" + std::to_string(i) + "]"); !st) return st;
    }
    for (std::size_t k = 0; k < ph.hand.keys.size(); ++k) {
      const HandKey& key = ph.hand.keys[k];
      if (key.grasp_id > 0 && !ids.count(key.grasp_id)) {
        return invalid_argument(where + ".hand.keys[" + std::to_string(k) + "].grasp: no object with id " +
                                std::to_string(key.grasp_id));
      }
    }
  }
  return {};
}

Scenario with_resolution(Scenario sc, int width, int height) {
  Intrinsics& K = sc.intrinsics;
  const double sx = static_cast<double>(width) / K.width;
  const double sy = static_cast<double>(height) / K.height;
  K.fx *= sx;
  K.fy *= sy;
  K.cx = (K.cx + 0.5) * sx - 0.5;
  K.cy = (K.cy + 0.5) * sy - 0.5;
  K.width = width;
  K.height = height;
  return sc;
}

Scenario with_frames(Scenario sc, int frames) {
  for (PhaseSpec& ph : sc.phases) {
    const double scale = ph.frames > 1 && frames > 1 ? static_cast<double>(frames - 1) / (ph.frames - 1) : 0.0;
    for (HandKey& k : ph.hand.keys) k.frame *= scale;
    for (CameraKey& k : ph.camera.keys) k.frame *= scale;
    ph.frames = frames;
  }
  return sc;
}

}  // namespace scenewatch::sim
