#pragma once
/// Whole-object changes (issue 10): mismatch evidence covers only the surface that entered or
/// left free space, which for a short move is the fringe of the object. The tabletop segmentation
/// of each frame gives whole objects: each cluster of evidence is replaced by the segmented
/// objects of its frame that it substantially belongs to (Config::completion_*_share), and
/// clusters of one kind completed to a shared object become one.
#include <vector>

#include "scenewatch/change/frame_objects.h"
#include "scenewatch/change/objects.h"

namespace scenewatch::change {

/// The objects that `evidence` (point indices) substantially belongs to: each carrying at least
/// config.completion_evidence_share of the evidence, or covered by it for at least
/// config.completion_object_share of its points. Ascending object indices; empty when none.
std::vector<int> explaining_objects(const std::vector<int>& evidence, const ObjectLabels& labels, const Config& config);

/// One frame of the pair as completion sees it. Not owning.
struct CompletionFrame {
  const Cloud* cloud_camera = nullptr;
  Pose T_world_camera = Pose::Identity();
  const ObjectLabels* objects = nullptr;
  Intrinsics K;  ///< for pixel regions of unorganized clouds
};

/// Completes removed clusters from `before`, added ones from `after`: a cluster's indices
/// become the union of its explaining objects plus its evidence that lies on no object, and its
/// points, box, centroid, colour and pixel region are recomputed from them (`completed` set).
/// A cluster no object explains stays as it is. A cluster several objects explain is first split
/// into one per object (two new objects side by side are two additions). Clusters of one kind
/// that share an object are merged into one. Order: as given, a merged cluster at the place of its first member.
std::vector<ChangeCluster> complete_clusters(std::vector<ChangeCluster> clusters, const CompletionFrame& before,
                                             const CompletionFrame& after, const Config& config);

}  // namespace scenewatch::change
