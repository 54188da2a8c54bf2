#pragma once
// The ontology as a stage of the pipeline (issue 33 item 2), run on request and not every frame
// (WorkingMemory::describe_objects): each tracked object's description, cached per object, and the
// completed primitive handed to the known surfaces so that later frames' expected view predicts
// the object's unseen side. Thread safe: one mutex, held while an object is described.
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <vector>

#include "known_surfaces.h"
#include "scenewatch/ontology/class_catalog.h"
#include "scenewatch/pipeline/object_class_info.h"
#include "scenewatch/pipeline/scene_snapshot.h"

namespace scenewatch::pipeline {

class ObjectDescriber {
 public:
  /// Completed surfaces go to `known` (which must outlive the describer).
  explicit ObjectDescriber(KnownSurfaces& known) : known_(known) {}

  /// One entry per object of `snapshot` (null for an object without points); see
  /// WorkingMemory::describe_objects.
  std::vector<std::shared_ptr<const ObjectClassInfo>> describe(const SceneSnapshot& snapshot,
                                                               const ontology::ClassCatalog& classes,
                                                               const DescribedCallback& on_described);
  /// The description of the object `object_id` of `snapshot`, cached as describe()'s; null when
  /// the snapshot has no such object or it has no points.
  std::shared_ptr<const ObjectClassInfo> describe_one(const SceneSnapshot& snapshot, std::uint64_t object_id,
                                                      const ontology::ClassCatalog& classes,
                                                      const DescribedCallback& on_described);
  /// Forgets every description (Reset clears the known surfaces they made: describe again).
  void clear();

 private:
  std::shared_ptr<const ObjectClassInfo> describe(const SceneSnapshot& snapshot, const TrackedObject& object,
                                                  const ontology::ClassCatalog& classes,
                                                  const DescribedCallback& on_described);

  struct Described {
    const void* points = nullptr;  // the snapshot's points it was made from
    double at_s = 0;
    std::shared_ptr<const ObjectClassInfo> info;
  };
  static constexpr double kDescribeAgainS = 2.0;

  KnownSurfaces& known_;
  std::mutex mutex_;  // described_, and one description at a time
  std::map<std::uint64_t, Described> described_;
};

}  // namespace scenewatch::pipeline
