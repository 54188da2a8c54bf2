#pragma once
/// The object list of the working memory: clusters of each frame matched to remembered objects,
/// with hysteresis both ways. A listed object must be an object, by evidence noise cannot give:
///  - it was seen in `confirm_frames` frames (2 by default: a fragment, a piece of an arm or a
///    noise cluster seen in one frame of a stream is not listed), except in the first frame the
///    tracker gets (after a start or a reset), whose objects are listed at first sight: a single
///    cloud sent once lists its objects. When frames follow, such an object is held to the same
///    rule: missed in `confirm_frames` frames in a row before its `confirm_frames`th sighting, it
///    leaves, as a tentative one would (a fragment the first frame showed once);
///  - it is as wide as the sensor can resolve at its range: both horizontal extents span at least
///    `min_extent_cells` cells of max(segmentation voxel, 2 sigma_z(range)) (a strip one voxel
///    wide along a rim or an edge is a fragment: its width was never measured, only quantized);
///  - clusters farther from the camera than `max_range_m` (where a Kinect's depth noise is as
///    large as a small object) are not objects.
/// An object leaves when the space it filled has been seen free in `gone_frames` frames (an
/// occluded or out-of-view object keeps its place), and silently when its surface is seen where
/// it was but no cluster stands for it there (a piece of a larger object, a fragment of an edge)
/// in as many frames in a row as half its sightings, at least `gone_frames`. A cluster that lies
/// mostly in a hand, an arm or the person's box starts no track, nor does one that lies mostly on
/// a listed object's surface as its fullest view saw it (a piece of it), nor one that does not rest
/// on its support (TrackerObservation::rests); an object whose place the frame sees on the
/// person's body in `gone_frames` frames leaves (never part of a person: a body in view before the
/// hand detector found its arm was listed at first sight).
///
/// The tracker raises no events: what changed in the scene is reported once, by the change
/// detector (OBJECT_ADDED / OBJECT_REMOVED / OBJECT_MOVED); the list is what GetObjects returns.
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <vector>

#include "scenewatch/core/scene.h"

namespace scenewatch::pipeline {

struct TrackingConfig {
  double match_distance_m = 0.05;  ///< a cluster matches a known object within this centroid distance
  /// An unmatched object's frame counts as "seen free" when this share of its sample points lies
  /// in space the frame saw through (or that the map holds free).
  double gone_free_fraction = 0.6;
  /// Sightings before a cluster joins the object list (1: at first sight); the first frame's
  /// clusters join at first sight whatever this is.
  int confirm_frames = 2;
  /// Cells of the resolution (see above) each horizontal extent must span; 0: no size check.
  double min_extent_cells = 2.0;
  int gone_frames = 2;       ///< frames of seen-free space before an object leaves the list
  double max_range_m = 2.0;  ///< clusters whose centroid is farther from the camera are ignored
  /// Each organized frame is segmented for the object list on every Nth pixel of every Nth row,
  /// the objects then carried back to every pixel (segmentation::segment_strided). N is at most
  /// this, and at most what keeps the samples within one segmentation voxel of each other at
  /// max_range_m on a surface facing the camera (floor(voxel_size_m fx / max_range_m): 2 for a
  /// VGA Kinect, 1 at 320x240). 1: every pixel.
  int segmentation_stride_px = 2;
};

/// One cluster of the frame, in world coordinates, with sample points of its surface.
struct TrackerObservation {
  ObjectCluster cluster;
  std::vector<Eigen::Vector3d> samples;
  /// Its points (world, thinned), kept with the object for what describes it (the ontology).
  std::shared_ptr<const std::vector<Eigen::Vector3d>> points;
  double range_m = 0.0;  ///< distance of its centroid from the camera
  /// The smallest extent the sensor resolves at that range: max(voxel, 2 sigma_z(range_m)).
  double resolution_m = 0.0;
  /// Half its box or more lies in a hand, an arm or the person's body seen in the same frame (each
  /// box grown by the segmentation's link distance): fingers and sleeves cut off the hand, a shirt
  /// or a leg the detector left out. It keeps a listed object's track but starts none.
  bool touches_person = false;
  /// It rests on its support (pipeline/src/support_contact.h): half or more of the surface beside
  /// its foot, in the support's band, faces up (or none of it could be judged). A cluster that
  /// crosses the support's height instead (the back of a chair beside a table) starts no track, and
  /// a listed object seen so in `gone_frames` sightings in a row leaves.
  bool rests = true;
};

/// NOT thread safe: owned by the working memory's writer.
class ObjectTracker {
 public:
  explicit ObjectTracker(const TrackingConfig& config) : config_(config) {}

  /// The share of `points` seen free (by the map, or by the last frame's rays).
  using FreeFraction = std::function<double(const std::vector<Eigen::Vector3d>& points)>;

  /// The share of `points` the frame sees where they are (the surface there, neither occluded nor
  /// gone): an object unmatched although seen so was not an object of its own.
  using SeenFraction = std::function<double(const std::vector<Eigen::Vector3d>& points)>;

  /// The share of `points` the frame sees where they are on a person's body: an object unmatched
  /// there in `gone_frames` frames in a row was a piece of the person, and leaves the list.
  using PersonFraction = SeenFraction;

  /// One frame. `free_fraction`, `seen_fraction` and `on_person` are asked about objects that were
  /// not matched.
  void update(std::vector<TrackerObservation> observations, double stamp_s, const FreeFraction& free_fraction,
              const SeenFraction& seen_fraction = {}, const PersonFraction& on_person = {});

  /// Confirmed objects, in the order they were confirmed.
  const std::vector<TrackedObject>& objects() const { return objects_; }
  std::size_t tentative() const { return tentative_.size(); }
  /// Sample points of a confirmed object's last observation (world).
  const std::vector<Eigen::Vector3d>* samples(std::uint64_t id) const;
  /// The points of a confirmed object's last observation (world), null when none are kept.
  std::shared_ptr<const std::vector<Eigen::Vector3d>> points(std::uint64_t id) const;

  /// Restores a saved list (objects are confirmed).
  void restore(std::vector<TrackedObject> objects, std::map<std::uint64_t, std::vector<Eigen::Vector3d>> samples,
               std::uint64_t next_id);
  std::uint64_t next_id() const { return next_id_; }
  /// Forgets a confirmed object (it became a foreground object, which the foreground tracks).
  void remove(std::uint64_t id);
  void reset();

 private:
  struct Track {
    TrackedObject object;
    std::vector<Eigen::Vector3d> samples;
    std::shared_ptr<const std::vector<Eigen::Vector3d>> points;
    int misses = 0;       ///< consecutive frames unmatched
    int seen_free = 0;    ///< consecutive frames unmatched with its space seen free
    int seen_unmatched = 0;  ///< consecutive frames unmatched with its surface seen in place
    int on_person = 0;       ///< consecutive frames unmatched with its place seen on a person
    int not_resting = 0;     ///< consecutive sightings crossing its support's height
    bool at_first_sight = false;  ///< listed in the tracker's first frame, unconfirmed
    /// Centroid of the observation it stood on in its last frame (a box on a box), if any.
    std::optional<Eigen::Vector3d> support_centroid;
    /// Its fullest view's points and their count: a piece of it seen again is no new object.
    std::shared_ptr<const std::vector<Eigen::Vector3d>> surface;
    std::size_t surface_point_count = 0;
  };
  void resolve_supports();
  void remember_surface(Track& t, double resolution_m) const;
  int piece_of(const TrackerObservation& o) const;
  TrackingConfig config_;
  std::vector<Track> tracks_;          ///< confirmed
  std::vector<Track> tentative_;       ///< seen, not yet confirmed
  std::vector<TrackedObject> objects_;  ///< the confirmed objects, as published
  std::uint64_t next_id_ = 1;
  std::uint64_t frames_ = 0;  ///< frames since the start, a reset or a restore (which counts as one)
};

}  // namespace scenewatch::pipeline
