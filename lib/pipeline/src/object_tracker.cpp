#include "scenewatch/pipeline/object_tracker.h"

#include <algorithm>
#include <tuple>

#include "scenewatch/core/voxel_set.h"

namespace scenewatch::pipeline {
namespace {

// Greedy nearest matching of observations to tracks: a pair within the match distance, or whose
// remembered centroid lies inside the observed box (a larger view of the same object).
std::vector<int> match(const std::vector<TrackerObservation>& obs, const std::vector<const TrackedObject*>& known,
                       double max_distance) {
  std::vector<std::tuple<double, int, int>> pairs;
  for (std::size_t c = 0; c < obs.size(); ++c)
    for (std::size_t o = 0; o < known.size(); ++o) {
      const double d = (obs[c].cluster.centroid - known[o]->cluster.centroid).norm();
      if (d <= max_distance || obs[c].cluster.box.contains(known[o]->cluster.centroid)) {
        pairs.emplace_back(d, static_cast<int>(c), static_cast<int>(o));
      }
    }
  std::sort(pairs.begin(), pairs.end());
  std::vector<int> obs_to_known(obs.size(), -1);
  std::vector<char> taken(known.size(), 0);
  for (const auto& [d, c, o] : pairs) {
    if (obs_to_known[c] >= 0 || taken[o]) continue;
    obs_to_known[c] = o;
    taken[o] = 1;
  }
  return obs_to_known;
}

// The share of `samples` within a cell (or its 26 neighbours) of `surface`'s points, on cells of
// `cell_m`: how much of an observation lies on a surface remembered for an object.
double share_on_surface(const std::vector<Eigen::Vector3d>& samples, const std::vector<Eigen::Vector3d>& surface,
                        double cell_m) {
  if (samples.empty() || surface.empty() || !(cell_m > 0)) return 0.0;
  VoxelSet cells(cell_m);
  for (const auto& p : surface) cells.insert(p);
  const auto near = std::count_if(samples.begin(), samples.end(), [&](const Eigen::Vector3d& p) { return cells.near(p); });
  return static_cast<double>(near) / static_cast<double>(samples.size());
}

}  // namespace

// The confirmed object (index into tracks_) whose remembered surface most of an unmatched
// observation lies on, -1 when none: a piece of it (a bin's far wall cut off by what fell in, a
// box's side beside a hand), seen again where that object was.
int ObjectTracker::piece_of(const TrackerObservation& o) const {
  for (std::size_t k = 0; k < tracks_.size(); ++k) {
    const Track& t = tracks_[k];
    if (t.surface && share_on_surface(o.samples, *t.surface, o.resolution_m) >= config_.gone_free_fraction)
      return static_cast<int>(k);
  }
  return -1;
}

void ObjectTracker::update(std::vector<TrackerObservation> observations, double stamp_s, const FreeFraction& free_fraction,
                           const SeenFraction& seen_fraction, const PersonFraction& on_person) {
  ++frames_;
  // The first frame lists what it sees (a single cloud sent once); later ones need confirming.
  const int confirm = frames_ == 1 ? 1 : config_.confirm_frames;
  for (auto& o : observations) o.cluster.indices.clear();  // indices belong to this frame only
  // What each observation stands on, by the centroid of the supporting observation (the indices
  // of supported_by are this frame's and do not survive matching).
  std::vector<std::optional<Eigen::Vector3d>> support(observations.size());
  for (std::size_t c = 0; c < observations.size(); ++c) {
    const int s = observations[c].cluster.supported_by;
    if (s >= 0 && static_cast<std::size_t>(s) < observations.size()) support[c] = observations[s].cluster.centroid;
  }
  std::size_t in_range = 0;
  const auto resolved = [&](const TrackerObservation& o) {
    const double need = config_.min_extent_cells * o.resolution_m;
    return std::min(o.cluster.box.extents.x(), o.cluster.box.extents.y()) >= need;
  };
  for (std::size_t c = 0; c < observations.size(); ++c) {
    if (observations[c].range_m > config_.max_range_m || !resolved(observations[c])) continue;
    if (in_range != c) {
      observations[in_range] = std::move(observations[c]);
      support[in_range] = support[c];
    }
    ++in_range;
  }
  observations.resize(in_range);
  support.resize(in_range);

  // Confirmed objects first, then the tentative ones get what is left.
  std::vector<const TrackedObject*> known;
  for (const auto& t : tracks_) known.push_back(&t.object);
  const std::size_t n_confirmed = known.size();
  for (const auto& t : tentative_) known.push_back(&t.object);
  const std::vector<int> matched = match(observations, known, config_.match_distance_m);

  std::vector<char> hit(known.size(), 0);
  for (std::size_t c = 0; c < observations.size(); ++c) {
    const int k = matched[c];
    if (k < 0 && (observations[c].touches_person || !observations[c].rests)) continue;
    if (k < 0) {
      if (const int whole = piece_of(observations[c]); whole >= 0) {
        // Seen, in part: the object stays as its largest piece left it.
        hit[static_cast<std::size_t>(whole)] = 1;
        tracks_[static_cast<std::size_t>(whole)].misses = 0;
        continue;
      }
      Track t;
      t.object.cluster = std::move(observations[c].cluster);
      t.object.first_seen_s = t.object.last_seen_s = stamp_s;
      t.object.observations = 1;
      t.samples = std::move(observations[c].samples);
      t.points = std::move(observations[c].points);
      t.support_centroid = support[c];
      remember_surface(t, observations[c].resolution_m);
      tentative_.push_back(std::move(t));
      continue;
    }
    hit[k] = 1;
    Track& t = static_cast<std::size_t>(k) < n_confirmed ? tracks_[k] : tentative_[k - n_confirmed];
    t.object.cluster = std::move(observations[c].cluster);
    t.object.last_seen_s = stamp_s;
    ++t.object.observations;
    t.samples = std::move(observations[c].samples);
    t.points = std::move(observations[c].points);
    t.support_centroid = support[c];
    t.misses = t.seen_free = t.seen_unmatched = t.on_person = 0;
    t.not_resting = observations[c].rests ? 0 : t.not_resting + 1;
    remember_surface(t, observations[c].resolution_m);
  }

  // Confirmed objects unmatched in this frame leave only when their space keeps being seen free.
  std::vector<Track> kept;
  for (std::size_t i = 0; i < tracks_.size(); ++i) {
    Track& t = tracks_[i];
    if (t.not_resting >= config_.gone_frames) continue;  // seen crossing its support's height
    if (!hit[i]) {
      ++t.misses;
      // Listed at first sight and not seen again: as a tentative object missed as often.
      if (t.at_first_sight && t.object.observations < config_.confirm_frames && t.misses >= config_.confirm_frames) continue;
      const bool person = on_person && on_person(t.samples) >= config_.gone_free_fraction;
      t.on_person = person ? t.on_person + 1 : 0;
      if (t.on_person >= config_.gone_frames) continue;
      const bool free = free_fraction && free_fraction(t.samples) >= config_.gone_free_fraction;
      t.seen_free = free ? t.seen_free + 1 : 0;
      if (t.seen_free >= config_.gone_frames) continue;
      const bool seen = !free && seen_fraction && seen_fraction(t.samples) >= config_.gone_free_fraction;
      t.seen_unmatched = seen ? t.seen_unmatched + 1 : 0;
      if (t.seen_unmatched >= std::max(config_.gone_frames, (t.object.observations + 1) / 2)) continue;
    }
    kept.push_back(std::move(t));
  }
  // Tentative ones: confirmed after enough sightings; dropped when missed as often.
  std::vector<Track> still_tentative;
  for (std::size_t i = 0; i < tentative_.size(); ++i) {
    Track& t = tentative_[i];
    const bool seen_now = n_confirmed + i < hit.size() ? hit[n_confirmed + i] != 0 : true;  // new ones are seen now
    if (!seen_now) ++t.misses;
    if (t.not_resting >= config_.gone_frames) continue;
    if (t.object.observations >= confirm && t.not_resting == 0) {
      t.object.id = next_id_++;
      t.misses = 0;
      t.at_first_sight = t.object.observations < config_.confirm_frames;
      kept.push_back(std::move(t));
    } else if (t.misses < config_.confirm_frames) {
      still_tentative.push_back(std::move(t));
    }
  }
  tracks_.swap(kept);
  tentative_.swap(still_tentative);
  resolve_supports();
  objects_.clear();
  for (const auto& t : tracks_) objects_.push_back(t.object);
}

// The surface an object is remembered by: its fullest view, as long as its views since lie on it
// (a part hidden by what fell in front of it is still there); one that does not is where the
// object is now (it moved).
void ObjectTracker::remember_surface(Track& t, double resolution_m) const {
  const bool fuller = t.object.cluster.point_count >= t.surface_point_count;
  if (!t.surface || fuller || share_on_surface(t.samples, *t.surface, resolution_m) < config_.gone_free_fraction) {
    t.surface = t.points;
    t.surface_point_count = t.object.cluster.point_count;
  }
}

void ObjectTracker::resolve_supports() {
  for (auto& t : tracks_) {
    t.object.supported_by = 0;
    if (!t.support_centroid) continue;
    for (const auto& other : tracks_) {
      if (&other != &t && other.object.cluster.centroid == *t.support_centroid) t.object.supported_by = other.object.id;
    }
  }
}

const std::vector<Eigen::Vector3d>* ObjectTracker::samples(std::uint64_t id) const {
  for (const auto& t : tracks_)
    if (t.object.id == id) return &t.samples;
  return nullptr;
}

std::shared_ptr<const std::vector<Eigen::Vector3d>> ObjectTracker::points(std::uint64_t id) const {
  for (const auto& t : tracks_)
    if (t.object.id == id) return t.points;
  return nullptr;
}

void ObjectTracker::restore(std::vector<TrackedObject> objects, std::map<std::uint64_t, std::vector<Eigen::Vector3d>> samples,
                            std::uint64_t next_id) {
  reset();
  for (auto& o : objects) {
    Track t;
    t.object = std::move(o);
    auto it = samples.find(t.object.id);
    if (it != samples.end()) t.samples = std::move(it->second);
    next_id = std::max(next_id, t.object.id + 1);
    tracks_.push_back(std::move(t));
  }
  next_id_ = next_id;
  frames_ = 1;  // a restored list goes on: the next frame's new clusters need confirming
  for (const auto& t : tracks_) objects_.push_back(t.object);
}

void ObjectTracker::remove(std::uint64_t id) {
  tracks_.erase(std::remove_if(tracks_.begin(), tracks_.end(), [&](const Track& t) { return t.object.id == id; }), tracks_.end());
  objects_.erase(std::remove_if(objects_.begin(), objects_.end(), [&](const TrackedObject& o) { return o.id == id; }), objects_.end());
}

void ObjectTracker::reset() {
  // next_id_ stays: an id is never given twice, not even across a reset.
  tracks_.clear();
  tentative_.clear();
  objects_.clear();
  frames_ = 0;
}

}  // namespace scenewatch::pipeline
