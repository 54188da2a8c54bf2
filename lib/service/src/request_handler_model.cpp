// The calls that change or keep the model as a whole: ClearBox, SaveModel, LoadModel, and the
// object classes (DefineClass, ListClasses).
#include <chrono>

#include "ontology_convert.h"
#include "proto_convert.h"
#include "request_handler_impl.h"
#include "scenewatch/ontology/class_catalog.h"
#include "scenewatch/service/model_directory.h"
#include "scenewatch/pipeline/working_memory.h"

namespace scenewatch::service {

Status RequestHandler::Impl::clear_box(const proto::ClearBox& msg, proto::Response& response) {
  if (!msg.has_box()) return invalid_argument("box is missing");
  auto box = convert::decode_box(msg.box(), "box");
  if (!box) return box.error();
  response.mutable_clear_box()->set_voxels_changed(memory.clear_box(*box));
  return {};
}

Status RequestHandler::Impl::require_model_dir() const {
  if (config.model_dir.empty()) {
    return unavailable("no model directory is configured (server.model_dir or --model-dir)");
  }
  return {};
}

Status RequestHandler::Impl::save_model(proto::Response& response) {
  if (Status s = require_model_dir(); !s) return s;
  if (Status s = service::save_model(memory, config.model_dir, config.keep_snapshots); !s) return s;
  response.mutable_save_model()->set_model_dir(config.model_dir.string());
  return {};
}

Status RequestHandler::Impl::load_model(proto::Response& response) {
  if (Status s = require_model_dir(); !s) return s;
  if (Status s = memory.load(config.model_dir); !s) return s;
  localization_notices.forget_cameras();
  auto* out = response.mutable_load_model();
  out->set_model_dir(config.model_dir.string());
  out->set_objects(memory.snapshot()->objects.size());
  return {};
}

Status RequestHandler::Impl::require_classes() const {
  if (!config.classes) return unavailable("this server has no object classes loaded");
  return {};
}

Status RequestHandler::Impl::define_class(const proto::DefineClass& msg, proto::Response& response) {
  if (Status s = require_classes(); !s) return s;
  auto parsed = ontology::parse_classes(msg.yaml(), "define_class.yaml");
  if (!parsed) return parsed.error();
  if (parsed->empty()) return invalid_argument("define_class.yaml: classes: the list is empty");
  const double now_s = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  auto* out = response.mutable_define_class();
  for (const auto& c : parsed->classes()) {
    if (Status s = config.classes->define(c, now_s); !s) return s;
    out->add_defined(c.name);
  }
  out->set_persisted(config.classes->persistent());
  return {};
}

Status RequestHandler::Impl::list_classes(proto::Response& response) {
  if (Status s = require_classes(); !s) return s;
  const ontology::ClassLibrary library = config.classes->library();
  auto* out = response.mutable_list_classes();
  const auto learnt = config.classes->learnt();
  for (const auto& c : library.classes()) {
    const auto found = learnt.find(c.name);
    convert::to_proto(c, found == learnt.end() ? nullptr : &found->second, out->add_classes());
  }
  out->set_yaml(ontology::to_yaml(library.classes()));
  return {};
}

}  // namespace scenewatch::service
