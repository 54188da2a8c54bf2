#pragma once
// The NextBestView call (issue 31): the target resolved from the memory (an object's or an event's
// box, a box, the workspace), the request checked and handed to the planning module.
#include "scenewatch.pb.h"
#include "scenewatch/core/result.h"
#include "scenewatch/ontology/class_catalog.h"
#include "scenewatch/pipeline/working_memory.h"
#include "scenewatch/service/suggested_views.h"

namespace scenewatch::service {

/// Answers one NextBestView from the memory's map. Bad requests (unknown object or event, bad
/// numbers) are errors naming the field. Thread safe as the memory's queries are.
/// An object target is described by `classes` (null: none; its box is the target), each new
/// description recorded there as GetObjects records it.
/// A successful answer's views are recorded in `suggested` (the live view draws them), when given.
Status next_best_view(pipeline::WorkingMemory& memory, const proto::NextBestView& msg, ontology::ClassCatalog* classes,
                      proto::NextBestViewReply* out, SuggestedViews* suggested = nullptr);

}  // namespace scenewatch::service
