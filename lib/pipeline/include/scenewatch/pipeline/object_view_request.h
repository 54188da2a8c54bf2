#pragma once
/// NextBestView's request for a tracked object (issue 31 item 3, attention: the view that
/// completes the object's model). The ontology's completion says which side is unseen: when a
/// class fits the object, the target is its completed primitive's surface less the face it stands
/// on (planning::complete_surface_request), so only voxels of the object's surface count, not the
/// unknown air of its box; otherwise the target is the object's box (complete_object_request).
#include <cstdint>
#include <string>

#include "scenewatch/core/result.h"
#include "scenewatch/ontology/class_catalog.h"
#include "scenewatch/pipeline/working_memory.h"
#include "scenewatch/planning/next_best_view.h"

namespace scenewatch::pipeline {

struct ObjectViewRequest {
  planning::NextBestViewRequest request;
  std::string target_description;  ///< what the target is and why, one sentence
};

/// The request for object `object_id`, described by `classes` (WorkingMemory::describe_object,
/// cached; each new description handed to `on_described`). No classes (null): the box. kNotFound
/// for an object that is not tracked. Thread safe as describe_object is.
Result<ObjectViewRequest> object_view_request(WorkingMemory& memory, std::uint64_t object_id,
                                              const ontology::ClassCatalog* classes, const DescribedCallback& on_described = {});

}  // namespace scenewatch::pipeline
