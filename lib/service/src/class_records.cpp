#include "class_records.h"

#include <optional>

#include <google/protobuf/util/json_util.h>

#include "ontology_convert.h"

namespace scenewatch::service {

// The instance keeps the class, the fitted primitive as JSON (the wire's field names) and when the
// object was last seen. Nothing here waits for the disk.
void record_description(ontology::ClassCatalog& classes, const TrackedObject& object,
                        const pipeline::ObjectClassInfo& described) {
  proto::ObjectClassInfo info;
  convert::to_proto(described, &info);
  ontology::InstanceRecord instance;
  instance.class_name = info.class_name();
  instance.time_s = object.last_seen_s;
  google::protobuf::util::JsonPrintOptions options;
  options.preserve_proto_field_names = true;
  if (info.has_primitive() && !google::protobuf::util::MessageToJsonString(info.primitive(), &instance.parameters_json, options).ok()) {
    instance.parameters_json.clear();
  }
  if (instance.parameters_json.empty()) instance.parameters_json = "{}";
  std::optional<DofFlags> handled_free;
  if (object.foreground && !object.foreground->handlings.empty()) handled_free = object.foreground->free;
  classes.record(instance, handled_free);
}

pipeline::DescribedCallback recorder(ontology::ClassCatalog& classes) {
  return [&classes](const TrackedObject& object, const pipeline::ObjectClassInfo& info) { record_description(classes, object, info); };
}

std::vector<std::shared_ptr<const pipeline::ObjectClassInfo>> describe_and_record(
    pipeline::WorkingMemory& memory, const pipeline::SceneSnapshot& snapshot, ontology::ClassCatalog& classes) {
  return memory.describe_objects(snapshot, classes, recorder(classes));
}

}  // namespace scenewatch::service
