#pragma once
// Ontology types on the wire (DefineClass, ListClasses, ObjectClassInfo). Private to the service.
#include "scenewatch.pb.h"
#include "scenewatch/ontology/describe.h"
#include "scenewatch/ontology/object_class.h"

namespace scenewatch::service::convert {

void to_proto(const ontology::ObjectClass& object_class, proto::ObjectClass* out);
/// What describe() found, for Object.ontology (not filled by GetObjects yet).
void to_proto(const ontology::ObjectDescription& description, proto::ObjectClassInfo* out);

}  // namespace scenewatch::service::convert
