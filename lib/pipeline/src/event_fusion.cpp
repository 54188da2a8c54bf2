#include "scenewatch/pipeline/event_fusion.h"

#include <algorithm>

namespace scenewatch::pipeline {
namespace {

constexpr std::size_t kMaxZones = 256;
constexpr int kClaimFrames = 10;  ///< appearance evidence is kept this long for a pending change

double area_of(const Event& e) {
  auto it = e.evidence.find("area_px");
  return it == e.evidence.end() ? 0.0 : it->second;
}

// Whole objects: a removal takes the listed object where it was, an addition this frame's
// segmented object where it is. The boxes of both join `geometric_boxes`.
void take_whole_objects(std::vector<Event>& geometric, std::vector<Aabb>& geometric_boxes,
                        const std::vector<TrackedObject>& objects, const std::vector<ObjectCluster>& clusters,
                        double margin_m) {
  for (auto& e : geometric) {
    const bool has_before = e.kind == EventKind::kObjectRemoved || e.kind == EventKind::kObjectMoved;
    const bool has_after = e.kind == EventKind::kObjectAdded || e.kind == EventKind::kObjectMoved;
    if (has_before) {
      const Eigen::Vector3d before_c = e.centroid_world - e.displacement_world.value_or(Eigen::Vector3d::Zero());
      for (const auto& o : objects) {
        if (!o.cluster.box.contains(before_c, margin_m)) continue;
        e.object_id = o.id;
        e.evidence["object_points_before"] = static_cast<double>(o.cluster.point_count);
        geometric_boxes.push_back(o.cluster.box.aabb());
        if (e.kind == EventKind::kObjectRemoved) e.box_world = e.box_world.united(o.cluster.box.aabb());
        break;
      }
    }
    if (has_after) {
      for (const auto& c : clusters) {
        if (!c.box.contains(e.centroid_world, margin_m)) continue;
        e.box_world = e.box_world.united(c.box.aabb());
        e.indices_after = c.indices;
        e.evidence["object_points_after"] = static_cast<double>(c.point_count);
        geometric_boxes.push_back(c.box.aabb());
        break;
      }
    }
  }
}

// Pieces of one object confirmed in the same frame are one fact: removals of the object that a
// move (or an earlier removal in this frame) already names.
std::vector<Event> merge_pieces(std::vector<Event> geometric) {
  std::vector<Event> merged;
  auto find_named = [&](std::uint64_t id) -> Event* {
    for (auto& m : merged)
      if (m.object_id == id && (m.kind == EventKind::kObjectMoved || m.kind == EventKind::kObjectRemoved)) return &m;
    return nullptr;
  };
  std::stable_sort(geometric.begin(), geometric.end(), [](const Event& a, const Event& b) {
    return (a.kind == EventKind::kObjectMoved) > (b.kind == EventKind::kObjectMoved);
  });
  for (auto& e : geometric) {
    Event* named = e.kind == EventKind::kObjectRemoved && e.object_id ? find_named(*e.object_id) : nullptr;
    if (named == nullptr) {
      merged.push_back(std::move(e));
      continue;
    }
    named->evidence["pieces"] = named->evidence.count("pieces") ? named->evidence["pieces"] + 1 : 2;
    named->pending_ids.insert(named->pending_ids.end(), e.pending_ids.begin(), e.pending_ids.end());
    if (named->kind == EventKind::kObjectRemoved) named->box_world = named->box_world.united(e.box_world);
  }
  return merged;
}

}  // namespace

std::vector<Event> EventFusion::update(const std::vector<Event>& appearance,
                                       const std::vector<change::ChangeCluster>& pending, std::vector<Event> geometric,
                                       std::vector<Aabb> geometric_boxes, bool familiar_view,
                                       const std::vector<TrackedObject>& objects,
                                       const std::vector<ObjectCluster>& clusters, std::uint32_t camera) {
  take_whole_objects(geometric, geometric_boxes, objects, clusters, config_.margin_m);
  age();
  geometric = drop_told_pieces(merge_pieces(std::move(geometric)));
  std::vector<const Event*> free_regions = claim_appearance(appearance, pending, geometric_boxes);
  for (auto& e : geometric) tell(e, geometric_boxes);
  // Appearance-only regions: from a familiar view, persistent in the world, or nothing.
  if (!familiar_view) free_regions.clear();
  std::vector<Event> out = std::move(geometric);
  follow_appearance(free_regions, camera, out);
  if (zones_.size() > kMaxZones) zones_.erase(zones_.begin(), zones_.end() - kMaxZones);
  return out;
}

void EventFusion::age() {
  for (auto& z : zones_) ++z.age;
  zones_.erase(std::remove_if(zones_.begin(), zones_.end(), [&](const Zone& z) { return z.age > config_.zone_frames; }),
               zones_.end());
  for (auto& c : claimed_) ++c.age;
  claimed_.erase(std::remove_if(claimed_.begin(), claimed_.end(), [](const Claimed& c) { return c.age > kClaimFrames; }),
                 claimed_.end());
}

// A geometric change inside the place of an earlier one of its kind is another piece of the same
// fact (the other side of an object that left or came, confirmed a few frames later).
std::vector<Event> EventFusion::drop_told_pieces(std::vector<Event> geometric) const {
  auto in_zone = [&](const Eigen::Vector3d& p, ZoneKind kind) {
    for (const auto& z : zones_)
      if (z.kind == kind && z.box.contains(p)) return true;
    return false;
  };
  std::vector<Event> fresh;
  for (auto& e : geometric) {
    const bool piece = (e.kind == EventKind::kObjectRemoved && in_zone(e.centroid_world, ZoneKind::kRemoved)) ||
                       (e.kind == EventKind::kObjectAdded && in_zone(e.centroid_world, ZoneKind::kAdded));
    if (!piece) fresh.push_back(std::move(e));
  }
  return fresh;
}

// Where geometry speaks, appearance is its evidence: regions over a pending or confirmed geometric
// change are kept as its evidence; the others, outside every zone, are returned.
std::vector<const Event*> EventFusion::claim_appearance(const std::vector<Event>& appearance,
                                                        const std::vector<change::ChangeCluster>& pending,
                                                        const std::vector<Aabb>& geometric_boxes) {
  std::vector<Aabb> geometry;
  for (const auto& c : pending) geometry.push_back(c.box_world.grown(config_.margin_m));
  for (const auto& b : geometric_boxes) geometry.push_back(b.grown(config_.margin_m));
  std::vector<const Event*> free_regions;
  for (const auto& region : appearance) {
    bool claimed = false;
    for (const auto& g : geometry) {
      if (!g.overlaps(region.box_world)) continue;
      claimed = true;
      claimed_.push_back(Claimed{g, region.score, area_of(region), 0});
    }
    bool silenced = false;
    for (const auto& z : zones_) silenced = silenced || z.box.contains(region.centroid_world);
    if (!claimed && !silenced) free_regions.push_back(&region);
  }
  return free_regions;
}

// A geometric event is told: its places become zones, it carries the appearance evidence gathered
// where it is, and appearance candidates at the same place are the same fact.
void EventFusion::tell(Event& e, const std::vector<Aabb>& geometric_boxes) {
  if (e.kind == EventKind::kObjectMoved) {
    const Eigen::Vector3d before_c = e.centroid_world - e.displacement_world.value_or(Eigen::Vector3d::Zero());
    for (const auto& b : geometric_boxes) {
      const Aabb place = b.grown(config_.margin_m);
      if (place.contains(before_c)) zones_.push_back(Zone{place, ZoneKind::kRemoved, 0});
    }
    zones_.push_back(Zone{e.box_world.grown(config_.margin_m), ZoneKind::kAdded, 0});
  } else {
    const ZoneKind kind = e.kind == EventKind::kObjectRemoved ? ZoneKind::kRemoved : ZoneKind::kAdded;
    zones_.push_back(Zone{e.box_world.grown(config_.margin_m), kind, 0});
  }
  const Aabb where = e.box_world.grown(config_.margin_m);
  double kl = 0.0, area = 0.0;
  for (const auto& c : claimed_) {
    if (!c.box.overlaps(where) || c.kl <= kl) continue;
    kl = c.kl;
    area = c.area_px;
  }
  if (kl > 0.0) {
    e.evidence["appearance_kl_mean"] = kl;
    e.evidence["appearance_area_px"] = area;
  }
  // Those candidates are this event now: their ids go with it.
  const auto same_fact = std::remove_if(candidates_.begin(), candidates_.end(),
                                        [&](const Candidate& c) { return where.overlaps(c.latest.box_world); });
  for (auto c = same_fact; c != candidates_.end(); ++c) e.pending_ids.push_back(c->id);
  candidates_.erase(same_fact, candidates_.end());
}

// Appearance-only regions persist at one place in the world, in frames of the camera that saw
// them, or are dropped; those seen often enough are appended to `out` as events.
void EventFusion::follow_appearance(const std::vector<const Event*>& free_regions, std::uint32_t camera,
                                    std::vector<Event>& out) {
  std::vector<char> matched(candidates_.size(), 0);
  for (const Event* region : free_regions) {
    int best = -1;
    double best_d = config_.match_m;
    for (std::size_t i = 0; i < candidates_.size(); ++i) {
      if (matched[i] || candidates_[i].camera != camera) continue;
      const double d = (candidates_[i].latest.centroid_world - region->centroid_world).norm();
      if (d <= best_d) {
        best_d = d;
        best = static_cast<int>(i);
      }
    }
    if (best < 0) {
      candidates_.push_back(Candidate{ids_->next(), *region, 1, 0, region->score, camera});
      matched.push_back(1);
      continue;
    }
    Candidate& c = candidates_[best];
    c.latest = *region;
    ++c.hits;
    c.misses = 0;
    c.best_kl = std::max(c.best_kl, region->score);
    matched[best] = 1;
  }
  std::vector<Candidate> kept;
  for (std::size_t i = 0; i < candidates_.size(); ++i) {
    Candidate& c = candidates_[i];
    if (!matched[i] && c.camera == camera) ++c.misses;
    if (c.hits >= config_.persistence_frames) {
      Event e = c.latest;
      e.evidence["frames_seen"] = c.hits;
      e.evidence["kl_mean_best"] = c.best_kl;
      e.pending_ids = {c.id};
      out.push_back(e);
      zones_.push_back(Zone{e.box_world.grown(config_.margin_m), ZoneKind::kAppearance, 0});
      continue;
    }
    if (c.misses < config_.persistence_frames) kept.push_back(std::move(c));
  }
  candidates_.swap(kept);
}

std::vector<change::PendingChange> EventFusion::pending() const {
  std::vector<change::PendingChange> out;
  for (const auto& c : candidates_) {
    out.push_back({c.id, change::PendingKind::kAppearance, c.latest.box_world, c.latest.centroid_world, c.hits,
                   config_.persistence_frames, c.camera});
  }
  return out;
}

void EventFusion::forget_camera(std::uint32_t camera) {
  candidates_.erase(std::remove_if(candidates_.begin(), candidates_.end(), [&](const Candidate& c) { return c.camera == camera; }),
                    candidates_.end());
}

void EventFusion::reset() {
  candidates_.clear();
  claimed_.clear();
  zones_.clear();
}

}  // namespace scenewatch::pipeline
