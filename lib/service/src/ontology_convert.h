#pragma once
// Ontology types on the wire (DefineClass, ListClasses, ObjectClassInfo). Private to the service.
#include "scenewatch.pb.h"
#include "scenewatch/ontology/class_catalog.h"
#include "scenewatch/ontology/object_class.h"
#include "scenewatch/pipeline/object_class_info.h"

namespace scenewatch::service::convert {

/// The class with its allowed motions: allowed_dofs = defined_dofs (config, DefineClass) with the
/// free DoFs of `learnt` (null: none learnt) added; learnt_free_dofs and learnt_frozen_dofs as learnt.
void to_proto(const ontology::ObjectClass& object_class, const ontology::LearntMotions* learnt, proto::ObjectClass* out);
/// What the pipeline's describer found (WorkingMemory::describe_objects), for Object.ontology.
void to_proto(const pipeline::ObjectClassInfo& info, proto::ObjectClassInfo* out);

}  // namespace scenewatch::service::convert
