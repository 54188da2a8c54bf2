// Persistence filter: candidates are matched frame to frame by kind and centroid; a candidate
// fires after persistence_frames hits, paired into a move when its opposite is ready too. A
// candidate keeps its id while it is matched; the change it fires names it (pending_ids).
#include "scenewatch/change/persistence.h"

#include <algorithm>
#include <limits>
#include <tuple>

namespace scenewatch::change {

namespace {
constexpr double kZoneMargin_m = 0.05;
constexpr std::size_t kMaxZones = 256;
}  // namespace

std::vector<ObjectChange> PersistenceFilter::update(const std::vector<ChangeCluster>& clusters,
                                                    std::vector<ChangeCluster>* pending,
                                                    std::vector<ChangeCluster>* absorbed, std::uint32_t camera) {
  std::vector<char> matched = match(clusters, absorbed, camera);
  drop_missing(matched);
  std::vector<char> done(candidates_.size(), 0);
  std::vector<ObjectChange> out = pair_moves(done);
  fire_singles(done, out, absorbed);
  remember_zones(out);
  keep_unfired(done, matched, pending);
  return out;
}

std::vector<char> PersistenceFilter::match(const std::vector<ChangeCluster>& clusters,
                                           std::vector<ChangeCluster>* absorbed, std::uint32_t camera) {
  std::vector<char> matched(candidates_.size(), 0);
  for (const auto& c : clusters) {
    bool in_zone = false;
    for (const auto& z : zones_) in_zone = in_zone || (z.kind == c.kind && z.box_world.contains(c.centroid_world));
    if (in_zone) {
      if (absorbed != nullptr) absorbed->push_back(c);
      continue;
    }
    int best = -1;
    double best_d = config_.persistence_match_m;
    for (std::size_t i = 0; i < candidates_.size(); ++i) {
      if (matched[i] || candidates_[i].camera != camera || candidates_[i].latest.kind != c.kind) continue;
      const double d = (candidates_[i].latest.centroid_world - c.centroid_world).norm();
      if (d <= best_d) {
        best_d = d;
        best = static_cast<int>(i);
      }
    }
    if (best < 0) {
      candidates_.push_back(Candidate{ids_->next(), c, 1, 0, 0, camera});
      matched.push_back(1);
      continue;
    }
    Candidate& cand = candidates_[best];
    cand.latest = c;
    ++cand.hits;
    cand.misses = 0;
    matched[best] = 1;
  }
  for (std::size_t i = 0; i < candidates_.size(); ++i) {
    if (!matched[i] && candidates_[i].camera == camera) ++candidates_[i].misses;
  }
  return matched;
}

void PersistenceFilter::drop_missing(std::vector<char>& matched) {
  // A candidate not seen for k frames in a row was noise (or left the view before it could be
  // confirmed).
  std::vector<Candidate> kept;
  std::vector<char> kept_matched;
  for (std::size_t i = 0; i < candidates_.size(); ++i) {
    if (candidates_[i].misses >= config_.persistence_frames) continue;
    kept.push_back(std::move(candidates_[i]));
    kept_matched.push_back(matched[i]);
  }
  candidates_.swap(kept);
  matched.swap(kept_matched);
}

bool PersistenceFilter::ready(const Candidate& c) const { return c.hits >= config_.persistence_frames; }

std::vector<ObjectChange> PersistenceFilter::pair_moves(std::vector<char>& done) const {
  std::vector<ObjectChange> out;
  // Moves: a ready removed candidate with the most similar ready added one.
  std::vector<std::tuple<double, int, int>> pairs;
  for (std::size_t r = 0; r < candidates_.size(); ++r) {
    if (!ready(candidates_[r]) || candidates_[r].latest.kind != ChangeKind::kRemoved) continue;
    for (std::size_t a = 0; a < candidates_.size(); ++a) {
      if (!ready(candidates_[a]) || candidates_[a].latest.kind != ChangeKind::kAdded) continue;
      const double s = move_similarity(candidates_[r].latest, candidates_[a].latest, config_);
      if (s > 0) pairs.emplace_back(-s, static_cast<int>(r), static_cast<int>(a));
    }
  }
  std::sort(pairs.begin(), pairs.end());
  for (const auto& [neg, r, a] : pairs) {
    if (done[r] || done[a]) continue;
    done[r] = done[a] = 1;
    ObjectChange c;
    c.kind = EventKind::kObjectMoved;
    c.before = candidates_[r].latest;
    c.after = candidates_[a].latest;
    c.similarity = -neg;
    c.pending_ids = {candidates_[r].id, candidates_[a].id};
    out.push_back(std::move(c));
  }
  return out;
}

bool PersistenceFilter::partner_coming(std::size_t i, const std::vector<char>& done) const {
  const Candidate& c = candidates_[i];
  for (std::size_t j = 0; j < candidates_.size(); ++j) {
    if (j == i || done[j] || ready(candidates_[j]) || candidates_[j].latest.kind == c.latest.kind) continue;
    const auto& removed = c.latest.kind == ChangeKind::kRemoved ? c.latest : candidates_[j].latest;
    const auto& added = c.latest.kind == ChangeKind::kAdded ? c.latest : candidates_[j].latest;
    if (move_similarity(removed, added, config_) > 0) return true;
  }
  return false;
}

void PersistenceFilter::fire_singles(std::vector<char>& done, std::vector<ObjectChange>& out,
                                     std::vector<ChangeCluster>* absorbed) {
  // Singles; one that may still become half of a move waits up to k frames for its partner.
  for (std::size_t i = 0; i < candidates_.size(); ++i) {
    Candidate& c = candidates_[i];
    if (done[i] || !ready(c)) continue;
    if (partner_coming(i, done) && c.waited < config_.persistence_frames) {
      ++c.waited;
      continue;
    }
    done[i] = 1;
    // Another piece of an object whose change fired in this frame (a vanished box seen through
    // in two parts): written into the model, no second event.
    ObjectChange* part_of_fired = nullptr;
    for (auto& f : out) {
      const auto& side = c.latest.kind == ChangeKind::kAdded ? f.after : f.before;
      if (part_of_fired == nullptr && side && side->box_world.grown(kZoneMargin_m).contains(c.latest.centroid_world)) {
        part_of_fired = &f;
      }
    }
    if (part_of_fired != nullptr) {
      part_of_fired->pending_ids.push_back(c.id);  // confirmed, as a piece of that change
      if (absorbed != nullptr) absorbed->push_back(c.latest);
      continue;
    }
    ObjectChange change;
    if (c.latest.kind == ChangeKind::kAdded) {
      change.kind = EventKind::kObjectAdded;
      change.after = c.latest;
    } else {
      change.kind = EventKind::kObjectRemoved;
      change.before = c.latest;
    }
    change.pending_ids = {c.id};
    out.push_back(std::move(change));
  }
}

void PersistenceFilter::remember_zones(const std::vector<ObjectChange>& fired) {
  auto add_zone = [&](const ChangeCluster& c) {
    zones_.push_back(Zone{c.kind, c.box_world.grown(kZoneMargin_m)});
  };
  for (const auto& c : fired) {
    if (c.before) add_zone(*c.before);
    if (c.after) add_zone(*c.after);
  }
  if (zones_.size() > kMaxZones) zones_.erase(zones_.begin(), zones_.end() - kMaxZones);
}

void PersistenceFilter::keep_unfired(const std::vector<char>& done, const std::vector<char>& matched,
                                     std::vector<ChangeCluster>* pending) {
  std::vector<Candidate> rest;
  for (std::size_t i = 0; i < candidates_.size(); ++i) {
    if (done[i]) continue;
    if (pending != nullptr && matched[i]) pending->push_back(candidates_[i].latest);
    rest.push_back(std::move(candidates_[i]));
  }
  candidates_.swap(rest);
}

std::vector<PendingChange> PersistenceFilter::pending() const {
  std::vector<PendingChange> out;
  for (const auto& c : candidates_) {
    const PendingKind kind = c.latest.kind == ChangeKind::kAdded ? PendingKind::kAdded : PendingKind::kRemoved;
    out.push_back({c.id, kind, c.latest.box_world, c.latest.centroid_world, c.hits, config_.persistence_frames, c.camera});
  }
  return out;
}

void PersistenceFilter::forget_camera(std::uint32_t camera) {
  candidates_.erase(std::remove_if(candidates_.begin(), candidates_.end(), [&](const Candidate& c) { return c.camera == camera; }),
                    candidates_.end());
}

}  // namespace scenewatch::change
