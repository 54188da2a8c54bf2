#pragma once
// What the service does with the ontology's descriptions of the tracked objects: each new one is an
// instance of its class seen, recorded in the class catalog (its fitted primitive, when the object
// was seen; a handled object's learnt free DoFs teach its class's motions). GetObjects and the live
// view both describe through here, so an object described for the page is recorded as well.
#include <memory>
#include <vector>

#include "scenewatch/ontology/class_catalog.h"
#include "scenewatch/pipeline/object_class_info.h"
#include "scenewatch/pipeline/scene_snapshot.h"
#include "scenewatch/pipeline/working_memory.h"

namespace scenewatch::service {

/// Records one new description in `classes`. The catalog queues the write for its own thread.
void record_description(ontology::ClassCatalog& classes, const TrackedObject& object,
                        const pipeline::ObjectClassInfo& described);

/// A callback that records each new description in `classes` (which must outlive it).
pipeline::DescribedCallback recorder(ontology::ClassCatalog& classes);

/// WorkingMemory::describe_objects with each new description recorded (record_description).
std::vector<std::shared_ptr<const pipeline::ObjectClassInfo>> describe_and_record(
    pipeline::WorkingMemory& memory, const pipeline::SceneSnapshot& snapshot, ontology::ClassCatalog& classes);

}  // namespace scenewatch::service
