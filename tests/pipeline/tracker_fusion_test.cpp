// The object list's hysteresis and the one-fact-one-event rules, each on hand-made inputs.
#include <gtest/gtest.h>

#include <functional>
#include <memory>

#include "scenewatch/pipeline/event_fusion.h"
#include "scenewatch/pipeline/object_tracker.h"

namespace scenewatch::pipeline {
namespace {

TrackerObservation seen_at(double x, double y, double range_m = 1.0) {
  TrackerObservation o;
  o.cluster.centroid = Eigen::Vector3d(x, y, 0.05);
  o.cluster.box.center = o.cluster.centroid;
  o.cluster.box.extents = Eigen::Vector3d(0.08, 0.08, 0.1);
  o.cluster.point_count = 500;
  o.samples = {o.cluster.centroid};
  o.range_m = range_m;
  return o;
}

// The tracker's evidence callbacks, answering the same share for any points.
std::function<double(const std::vector<Eigen::Vector3d>&)> share(double s) {
  return [s](const std::vector<Eigen::Vector3d>&) { return s; };
}

const ObjectTracker::FreeFraction kSeenFree = share(1.0);
const ObjectTracker::FreeFraction kOccluded = share(0.0);

TEST(ObjectTracker, JoinsAfterConfirmFramesAndNoiseNeverJoins) {
  TrackingConfig config;
  config.confirm_frames = 3;
  ObjectTracker tracker(config);
  tracker.update({}, 0, kOccluded);  // the first frame lists at first sight: this one saw nothing
  tracker.update({seen_at(0, 0), seen_at(0.5, 0.5)}, 1, kOccluded);
  tracker.update({seen_at(0.005, 0)}, 2, kOccluded);  // the noise cluster at (0.5, 0.5) is gone
  EXPECT_TRUE(tracker.objects().empty()) << "two sightings are not enough";
  tracker.update({seen_at(0.01, 0)}, 3, kOccluded);
  ASSERT_EQ(tracker.objects().size(), 1u);
  EXPECT_EQ(tracker.objects()[0].observations, 3);
  for (int i = 4; i < 8; ++i) tracker.update({seen_at(0.01, 0)}, i, kOccluded);
  ASSERT_EQ(tracker.objects().size(), 1u) << "the noise cluster never joined";
  EXPECT_EQ(tracker.tentative(), 0u) << "and was forgotten";
}

// A single cloud sent once lists its objects; in a stream, a cluster seen in one frame is not an
// object (a fragment, a piece of an arm, noise) until it is seen again.
TEST(ObjectTracker, TheFirstFrameListsAtFirstSightLaterFramesNeedConfirming) {
  ObjectTracker tracker(TrackingConfig{});  // confirm_frames 2
  tracker.update({seen_at(0, 0)}, 1, kOccluded);
  ASSERT_EQ(tracker.objects().size(), 1u) << "the first frame: listed at first sight";
  tracker.update({seen_at(0, 0), seen_at(0.3, 0)}, 2, kOccluded);
  EXPECT_EQ(tracker.objects().size(), 1u) << "a new cluster in the second frame waits";
  tracker.update({seen_at(0, 0), seen_at(0.3, 0)}, 3, kOccluded);
  ASSERT_EQ(tracker.objects().size(), 2u) << "seen twice: listed";
  tracker.update({seen_at(0, 0), seen_at(0.3, 0), seen_at(0.6, 0)}, 4, kOccluded);  // a fragment, once
  for (int i = 5; i < 8; ++i) tracker.update({seen_at(0, 0), seen_at(0.3, 0)}, i, kOccluded);
  EXPECT_EQ(tracker.objects().size(), 2u) << "the fragment seen once never joined";
  EXPECT_EQ(tracker.tentative(), 0u) << "and was forgotten";
  tracker.reset();
  tracker.update({seen_at(0.6, 0)}, 8, kOccluded);
  EXPECT_EQ(tracker.objects().size(), 1u) << "after a reset the first frame lists again";
  const auto saved = tracker.objects();
  ObjectTracker restored(TrackingConfig{});
  restored.restore(saved, {}, tracker.next_id());
  restored.update({seen_at(0.6, 0), seen_at(0, 0)}, 9, kOccluded);
  EXPECT_EQ(restored.objects().size(), 1u) << "a restored list goes on: the new cluster waits";
}

// What the first frame listed at first sight must be seen again, as any other object: a fragment
// that frame showed once leaves after confirm_frames frames without it, occluded or not; one seen
// again stays through an occlusion.
TEST(ObjectTracker, WhatTheFirstFrameListedLeavesUnlessSeenAgain) {
  ObjectTracker tracker(TrackingConfig{});  // confirm_frames 2
  tracker.update({seen_at(0, 0), seen_at(0.3, 0), seen_at(0.6, 0)}, 1, kOccluded);
  ASSERT_EQ(tracker.objects().size(), 3u) << "the first frame: listed at first sight";
  tracker.update({seen_at(0, 0), seen_at(0.3, 0)}, 2, kOccluded);
  EXPECT_EQ(tracker.objects().size(), 3u) << "one frame without it: it stays";
  tracker.update({seen_at(0.3, 0)}, 3, kOccluded);
  ASSERT_EQ(tracker.objects().size(), 2u) << "two frames without it, never seen again: it leaves";
  EXPECT_NEAR(tracker.objects()[0].cluster.centroid.x(), 0.0, 1e-9) << "the one seen again stays, though unseen now";
  for (int i = 4; i < 10; ++i) tracker.update({seen_at(0.3, 0)}, i, kOccluded);
  EXPECT_EQ(tracker.objects().size(), 2u) << "confirmed, then occluded: it keeps its place";
}

TEST(ObjectTracker, LeavesOnlyWhenItsSpaceIsSeenFreeInGoneFrames) {
  TrackingConfig config;
  config.gone_frames = 2;
  ObjectTracker tracker(config);
  tracker.update({seen_at(0, 0), seen_at(0.3, 0)}, 1, kOccluded);
  ASSERT_EQ(tracker.objects().size(), 2u) << "the first frame: listed at first sight";
  tracker.update({seen_at(0, 0), seen_at(0.3, 0)}, 2, kOccluded);  // and confirmed
  for (int i = 3; i < 10; ++i) tracker.update({seen_at(0.3, 0)}, i, kOccluded);
  EXPECT_EQ(tracker.objects().size(), 2u) << "unseen but occluded: it keeps its place";
  tracker.update({seen_at(0.3, 0)}, 10, kSeenFree);
  EXPECT_EQ(tracker.objects().size(), 2u) << "one frame of free space is not enough";
  tracker.update({seen_at(0.3, 0)}, 11, kSeenFree);
  ASSERT_EQ(tracker.objects().size(), 1u);
  EXPECT_NEAR(tracker.objects()[0].cluster.centroid.x(), 0.3, 1e-9);
}

TEST(ObjectTracker, FarClustersAreNotObjectsAndIdsSurviveARestore) {
  ObjectTracker tracker(TrackingConfig{});
  tracker.update({seen_at(0, 0, 1.2), seen_at(2, 2, 3.0)}, 1, kOccluded);
  ASSERT_EQ(tracker.objects().size(), 1u) << "beyond max_range_m (2 m): not an object";
  const auto saved = tracker.objects();
  ObjectTracker restored(TrackingConfig{});
  restored.restore(saved, {}, tracker.next_id());
  ASSERT_EQ(restored.objects().size(), 1u);
  EXPECT_EQ(restored.objects()[0].id, saved[0].id);
  restored.update({seen_at(0, 0), seen_at(0.4, 0)}, 2, kOccluded);
  restored.update({seen_at(0, 0), seen_at(0.4, 0)}, 3, kOccluded);  // the new one confirmed
  ASSERT_EQ(restored.objects().size(), 2u);
  EXPECT_EQ(restored.objects()[0].id, saved[0].id) << "matched, same id";
  EXPECT_GT(restored.objects()[1].id, saved[0].id) << "a new id, never one given before";
}

// A strip one resolution cell wide (a rim, an edge's fringe) is a fragment, not an object; an
// object 2 cm wide at 1 m (resolution: the 1 cm voxel) is listed.
TEST(ObjectTracker, StripsNarrowerThanTheSensorResolvesAreNotObjects) {
  ObjectTracker tracker(TrackingConfig{});
  TrackerObservation strip = seen_at(0, 0), thin = seen_at(0.3, 0);
  strip.cluster.box.extents = Eigen::Vector3d(0.15, 0.012, 0.04);
  thin.cluster.box.extents = Eigen::Vector3d(0.10, 0.021, 0.04);
  strip.resolution_m = thin.resolution_m = 0.01;
  tracker.update({strip, thin}, 1, kOccluded);
  ASSERT_EQ(tracker.objects().size(), 1u);
  EXPECT_NEAR(tracker.objects()[0].cluster.centroid.x(), 0.3, 1e-9);
  // Farther away the noise sets the cell (2 sigma_z above the voxel): with a 2 cm cell, the same
  // 2.1 cm is not resolved.
  thin.resolution_m = 0.02;
  ObjectTracker far(TrackingConfig{});
  far.update({thin}, 1, kOccluded);
  EXPECT_TRUE(far.objects().empty());
}

// An object whose surface is seen where it was, with no cluster of its own there (a piece of a
// larger object, a fragment), leaves silently after half its sightings, at least gone_frames; an
// object merely hidden or out of view keeps its place.
TEST(ObjectTracker, SeenInPlaceWithoutAClusterLeavesAfterHalfItsSightings) {
  TrackingConfig config;
  config.gone_frames = 2;
  const ObjectTracker::SeenFraction seen = share(1.0), hidden = share(0.0);
  ObjectTracker tracker(config);
  for (int i = 0; i < 10; ++i) tracker.update({seen_at(0, 0), seen_at(0.3, 0)}, i, kOccluded, seen);
  tracker.update({seen_at(0.3, 0), seen_at(0.6, 0)}, 10, kOccluded, seen);  // a fragment at 0.6, twice
  tracker.update({seen_at(0.3, 0), seen_at(0.6, 0)}, 11, kOccluded, hidden);
  ASSERT_EQ(tracker.objects().size(), 3u);
  for (int i = 12; i < 30; ++i) tracker.update({seen_at(0.3, 0)}, i, kOccluded, hidden);
  EXPECT_EQ(tracker.objects().size(), 3u) << "hidden: nothing leaves";
  tracker.update({seen_at(0.3, 0)}, 30, kOccluded, seen);
  EXPECT_EQ(tracker.objects().size(), 3u) << "one frame is not enough";
  tracker.update({seen_at(0.3, 0)}, 31, kOccluded, seen);
  ASSERT_EQ(tracker.objects().size(), 2u) << "the fragment seen twice leaves after gone_frames";
  for (int i = 32; i < 34; ++i) tracker.update({seen_at(0.3, 0)}, i, kOccluded, seen);
  EXPECT_EQ(tracker.objects().size(), 2u) << "the object seen 10 times stays for 5 frames";
  tracker.update({seen_at(0.3, 0)}, 34, kOccluded, seen);
  ASSERT_EQ(tracker.objects().size(), 1u);
  EXPECT_NEAR(tracker.objects()[0].cluster.centroid.x(), 0.3, 1e-9);
}

// A cluster that lies mostly in a hand or an arm (fingers, a sleeve) starts no track; a listed
// object the hand reaches keeps its own.
TEST(ObjectTracker, PiecesOfAPersonStartNoTrack) {
  ObjectTracker tracker(TrackingConfig{});
  tracker.update({seen_at(0, 0)}, 1, kOccluded);
  TrackerObservation held = seen_at(0.005, 0), finger = seen_at(0.4, 0);
  held.touches_person = finger.touches_person = true;
  tracker.update({held, finger}, 2, kOccluded);
  ASSERT_EQ(tracker.objects().size(), 1u) << "the finger is not listed";
  EXPECT_EQ(tracker.objects()[0].observations, 2) << "the object in reach keeps its track";
  tracker.update({seen_at(0.4, 0)}, 3, kOccluded);
  tracker.update({seen_at(0.4, 0)}, 4, kOccluded);
  EXPECT_EQ(tracker.objects().size(), 2u) << "seen apart from the hand, it is listed";
}

// A body in view before the hand detector found its arm is listed at first sight; once the frames
// see its place on the person (gone_frames in a row), it leaves. Seen on the person only once, or
// hidden, it stays.
TEST(ObjectTracker, AnObjectWhosePlaceIsSeenOnThePersonLeaves) {
  TrackingConfig config;
  config.gone_frames = 2;
  const ObjectTracker::PersonFraction on_person = share(1.0), elsewhere = share(0.0);
  ObjectTracker tracker(config);
  for (int i = 0; i < 10; ++i) tracker.update({seen_at(0, 0), seen_at(0.3, 0)}, i, kOccluded, {}, elsewhere);
  tracker.update({seen_at(0, 0)}, 10, kOccluded, {}, on_person);
  tracker.update({seen_at(0, 0)}, 11, kOccluded, {}, elsewhere);
  tracker.update({seen_at(0, 0)}, 12, kOccluded, {}, on_person);
  ASSERT_EQ(tracker.objects().size(), 2u) << "on the person in frames apart: it stays";
  tracker.update({seen_at(0, 0)}, 13, kOccluded, {}, on_person);
  ASSERT_EQ(tracker.objects().size(), 1u) << "twice in a row: a piece of the person";
  EXPECT_NEAR(tracker.objects()[0].cluster.centroid.x(), 0.0, 1e-9);
  tracker.update({seen_at(0, 0)}, 14, kOccluded, {}, on_person);
  EXPECT_EQ(tracker.objects().size(), 1u) << "a matched object is never asked";
}

// A cluster that crosses its support's height (not `rests`) starts no track, and a listed one seen
// so in gone_frames sightings in a row leaves; seen so once, it stays.
TEST(ObjectTracker, WhatCrossesItsSupportsHeightIsNotListed) {
  TrackingConfig config;
  config.gone_frames = 2;
  ObjectTracker tracker(config);
  TrackerObservation crossing = seen_at(0.4, 0);
  crossing.rests = false;
  tracker.update({seen_at(0, 0), crossing}, 0, kOccluded);
  ASSERT_EQ(tracker.objects().size(), 1u) << "not even at first sight";
  for (int i = 1; i < 4; ++i) tracker.update({seen_at(0, 0), crossing}, i, kOccluded);
  EXPECT_EQ(tracker.objects().size(), 1u);
  EXPECT_EQ(tracker.tentative(), 0u);
  TrackerObservation once = seen_at(0, 0);
  once.rests = false;
  tracker.update({once}, 4, kOccluded);
  tracker.update({seen_at(0, 0)}, 5, kOccluded);
  tracker.update({once}, 6, kOccluded);
  ASSERT_EQ(tracker.objects().size(), 1u) << "crossing in sightings apart: it stays";
  tracker.update({once}, 7, kOccluded);
  EXPECT_TRUE(tracker.objects().empty()) << "twice in a row: it leaves";
}

// Points on a line from `from` to `to`, `n` of them: a stand-in for an object's surface.
std::shared_ptr<std::vector<Eigen::Vector3d>> strip(const Eigen::Vector3d& from, const Eigen::Vector3d& to, int n) {
  auto pts = std::make_shared<std::vector<Eigen::Vector3d>>();
  for (int i = 0; i < n; ++i) pts->push_back(from + (to - from) * i / (n - 1.0));
  return pts;
}

TrackerObservation surface_seen(const Eigen::Vector3d& from, const Eigen::Vector3d& to, int n) {
  TrackerObservation o = seen_at(0.5 * (from + to).x(), 0.5 * (from + to).y());
  o.points = strip(from, to, n);
  o.samples = *o.points;
  o.cluster.point_count = static_cast<std::size_t>(n);
  o.cluster.box.extents = (to - from).cwiseAbs() + Eigen::Vector3d::Constant(0.02);
  o.resolution_m = 0.01;
  return o;
}

// A bin seen whole, then in two pieces (a toy fell in): the larger piece keeps the bin's track, the
// other, on the surface the whole view saw, is no new object. Something new beside it is.
TEST(ObjectTracker, APieceOfAListedObjectIsNoNewObject) {
  ObjectTracker tracker(TrackingConfig{});
  const Eigen::Vector3d a(0, 0, 0.05), b(0.4, 0, 0.05), m(0.25, 0, 0.05);
  tracker.update({surface_seen(a, b, 400)}, 0, kOccluded);
  ASSERT_EQ(tracker.objects().size(), 1u);
  for (int i = 1; i < 5; ++i) tracker.update({surface_seen(a, m, 250), surface_seen(m + Eigen::Vector3d(0.05, 0, 0), b, 100)}, i, kOccluded);
  ASSERT_EQ(tracker.objects().size(), 1u) << "the far piece lies on the bin as first seen";
  EXPECT_EQ(tracker.objects()[0].observations, 5);
  EXPECT_EQ(tracker.tentative(), 0u);
  const Eigen::Vector3d c(0, 0.3, 0.05), d(0.2, 0.3, 0.05);
  for (int i = 5; i < 7; ++i) tracker.update({surface_seen(a, m, 250), surface_seen(c, d, 200)}, i, kOccluded);
  EXPECT_EQ(tracker.objects().size(), 2u) << "something 30 cm away is new";
  // The bin is pushed 20 cm, 4 cm a frame, seen less fully than at first: its remembered surface
  // follows it, so what then stands where it was is new.
  for (int i = 7; i < 12; ++i) {
    const Eigen::Vector3d shift(0, -0.04 * (i - 7), 0);  // seen whole in place first
    tracker.update({surface_seen(a + shift, b + shift, 300), surface_seen(c, d, 200)}, i, kOccluded);
  }
  ASSERT_EQ(tracker.objects().size(), 2u);
  for (int i = 12; i < 14; ++i)
    tracker.update({surface_seen(a + Eigen::Vector3d(0, -0.2, 0), b + Eigen::Vector3d(0, -0.2, 0), 300), surface_seen(c, d, 200),
                    surface_seen(a, m, 250)},
                   i, kOccluded);
  EXPECT_EQ(tracker.objects().size(), 3u) << "what stands where the bin was before it moved is new";
}

Event region_at(double x, double y, double kl = 15.0) {
  Event e;
  e.kind = EventKind::kAppearanceChange;
  e.score = kl;
  e.centroid_world = Eigen::Vector3d(x, y, 0.8);
  e.box_world = {e.centroid_world - Eigen::Vector3d::Constant(0.03), e.centroid_world + Eigen::Vector3d::Constant(0.03)};
  e.evidence["area_px"] = 200;
  return e;
}

Event geometric_at(EventKind kind, double x, double y) {
  Event e;
  e.kind = kind;
  e.centroid_world = Eigen::Vector3d(x, y, 0.8);
  e.box_world = {e.centroid_world - Eigen::Vector3d::Constant(0.04), e.centroid_world + Eigen::Vector3d::Constant(0.04)};
  return e;
}

TEST(EventFusion, AnAppearanceChangeMustPersistInAFamiliarView) {
  EventFusion fusion;
  for (int i = 0; i < 10; ++i) {
    EXPECT_TRUE(fusion.update({region_at(0.2, 0.1)}, {}, {}, {}, /*familiar_view=*/false).empty())
        << "a view seen for the first time: surprise is no change on its own";
  }
  // Regions that move with the camera (misalignment, reflections) never persist.
  for (int i = 0; i < 10; ++i) EXPECT_TRUE(fusion.update({region_at(0.1 * i, 0)}, {}, {}, {}, true).empty());
  std::vector<Event> told;
  for (int i = 0; i < 10; ++i) {
    auto out = fusion.update({region_at(0.5 + 0.005 * i, 0.5)}, {}, {}, {}, true);
    if (!out.empty()) {
      EXPECT_EQ(i, 4) << "persistence_frames 5: told on the fifth sighting";
    }
    told.insert(told.end(), out.begin(), out.end());
  }
  ASSERT_EQ(told.size(), 1u) << "once, then its place is silent";
  EXPECT_EQ(told[0].kind, EventKind::kAppearanceChange);
  EXPECT_EQ(told[0].evidence.at("frames_seen"), 5.0);
}

// Issue 31: appearance candidates are pending changes too, in the id space they share with the
// geometric ones; the event that tells a candidate names its id.
TEST(EventFusion, AppearanceCandidatesAreListedUntilTold) {
  auto ids = std::make_shared<change::PendingIds>();
  EXPECT_EQ(ids->next(), 1u) << "say the persistence filter took 1";
  EventFusion fusion({}, ids);
  for (int i = 0; i < 4; ++i) {
    EXPECT_TRUE(fusion.update({region_at(0.5 + 0.005 * i, 0.5)}, {}, {}, {}, true, {}, {}, /*camera=*/3).empty());
    const auto listed = fusion.pending();
    ASSERT_EQ(listed.size(), 1u);
    EXPECT_EQ(listed[0].id, 2u) << "the same id while it is matched";
    EXPECT_EQ(listed[0].kind, change::PendingKind::kAppearance);
    EXPECT_EQ(listed[0].hits, i + 1);
    EXPECT_EQ(listed[0].hits_needed, 5);
    EXPECT_EQ(listed[0].camera, 3u);
    EXPECT_NEAR(listed[0].centroid_world.x(), 0.5 + 0.005 * i, 1e-12);
  }
  auto told = fusion.update({region_at(0.52, 0.5)}, {}, {}, {}, true, {}, {}, 3);
  ASSERT_EQ(told.size(), 1u);
  EXPECT_EQ(told[0].pending_ids, std::vector<std::uint64_t>{2});
  EXPECT_TRUE(fusion.pending().empty());

  // A candidate where a geometric change is then confirmed is that change: its id goes with it.
  fusion.update({region_at(-0.3, 0.0)}, {}, {}, {}, true, {}, {}, 3);
  ASSERT_EQ(fusion.pending().size(), 1u);
  EXPECT_EQ(fusion.pending()[0].id, 3u);
  Event added = geometric_at(EventKind::kObjectAdded, -0.3, 0.0);
  added.pending_ids = {1};
  told = fusion.update({}, {}, {added}, {added.box_world}, true, {}, {}, 3);
  ASSERT_EQ(told.size(), 1u);
  EXPECT_EQ(told[0].pending_ids, (std::vector<std::uint64_t>{1, 3}));
  EXPECT_TRUE(fusion.pending().empty());
}

TEST(EventFusion, SurpriseWhereGeometryChangesIsItsEvidence) {
  EventFusion fusion;
  change::ChangeCluster pending;
  pending.box_world = {{0.16, 0.06, 0.76}, {0.24, 0.14, 0.84}};
  pending.centroid_world = {0.2, 0.1, 0.8};
  for (int i = 0; i < 2; ++i) EXPECT_TRUE(fusion.update({region_at(0.2, 0.1, 20.0 + i)}, {pending}, {}, {}, true).empty());
  const Event added = geometric_at(EventKind::kObjectAdded, 0.2, 0.1);
  auto out = fusion.update({region_at(0.2, 0.1)}, {}, {added}, {added.box_world}, true);
  ASSERT_EQ(out.size(), 1u) << "one fact, one event";
  EXPECT_EQ(out[0].kind, EventKind::kObjectAdded);
  EXPECT_DOUBLE_EQ(out[0].evidence.at("appearance_kl_mean"), 21.0) << "the strongest surprise seen there";
  for (int i = 0; i < 5; ++i) EXPECT_TRUE(fusion.update({region_at(0.2, 0.1)}, {}, {}, {}, true).empty());
}

TEST(EventFusion, PiecesOfOneObjectAreOneEventButAReturnIsNews) {
  EventFusion fusion;
  TrackedObject box;
  box.id = 7;
  box.cluster.box.center = {0.1, 0.0, 0.85};
  box.cluster.box.extents = {0.24, 0.12, 0.2};
  // Two pieces of the same listed object confirmed in one frame: one removal, with its id and box.
  const Event a = geometric_at(EventKind::kObjectRemoved, 0.02, 0.0), b = geometric_at(EventKind::kObjectRemoved, 0.18, 0.0);
  auto out = fusion.update({}, {}, {a, b}, {a.box_world, b.box_world}, true, {box});
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].object_id, std::optional<std::uint64_t>(7));
  EXPECT_LE(out[0].box_world.min.x(), -0.02) << "the whole object's box";
  EXPECT_GE(out[0].box_world.max.x(), 0.22);
  // A later piece inside the removed object's place is the same fact.
  const Event c = geometric_at(EventKind::kObjectRemoved, 0.1, 0.03);
  EXPECT_TRUE(fusion.update({}, {}, {c}, {c.box_world}, true).empty());
  // Something put back there is news.
  const Event back = geometric_at(EventKind::kObjectAdded, 0.1, 0.0);
  out = fusion.update({}, {}, {back}, {back.box_world}, true);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].kind, EventKind::kObjectAdded);
}

}  // namespace
}  // namespace scenewatch::pipeline
