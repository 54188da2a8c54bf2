#include "ontology_convert.h"

#include <algorithm>

#include "proto_convert.h"

namespace scenewatch::service::convert {
namespace {

void to_proto(const ontology::Range& r, proto::Range* out) {
  out->set_min(r.min);
  out->set_max(r.max);
}

}  // namespace

void to_proto(const ontology::ObjectClass& c, const ontology::LearntMotions* learnt, proto::ObjectClass* out) {
  out->set_name(c.name);
  out->set_shape(ontology::to_string(c.shape));
  if (c.shape != ontology::ClassShape::kBox) to_proto(c.radius_m, out->mutable_radius_m());
  if (c.shape != ontology::ClassShape::kSphere) to_proto(c.height_m, out->mutable_height_m());
  if (c.shape == ontology::ClassShape::kFrustum) to_proto(c.taper_deg, out->mutable_taper_deg());
  for (const auto& r : c.size_m) to_proto(r, out->add_size_m());
  out->set_axis(c.axis == ontology::ClassAxis::kUpright ? "upright" : "any");
  out->set_axis_tolerance_deg(c.axis_tolerance_deg);
  out->set_top(c.top == ontology::ClassTop::kOpen ? "open" : c.top == ontology::ClassTop::kClosed ? "closed" : "any");
  out->set_max_rms_m(c.max_rms_m);
  out->set_min_explained(c.min_explained);
  out->set_min_coverage_deg(c.min_coverage_deg);
  for (const auto& g : c.grasps) {
    auto* p = out->add_grasps();
    p->set_name(g.name);
    p->set_kind(ontology::to_string(g.kind));
    p->set_height_fraction(g.height_fraction);
  }
  for (const auto& d : c.allowed_dofs) out->add_defined_dofs(d);
  for (int k = 0; k < kDofCount; ++k) {
    const std::string dof = to_string(static_cast<Dof>(k));
    const bool defined = std::find(c.allowed_dofs.begin(), c.allowed_dofs.end(), dof) != c.allowed_dofs.end();
    if (defined || (learnt && learnt->free[static_cast<std::size_t>(k)])) out->add_allowed_dofs(dof);
  }
  if (learnt) {
    for (const auto& d : learnt->names(true)) out->add_learnt_free_dofs(d);
    for (const auto& d : learnt->names(false)) out->add_learnt_frozen_dofs(d);
  }
  out->set_description(c.description);
}

void to_proto(const pipeline::ObjectClassInfo& d, proto::ObjectClassInfo* out) {
  out->set_class_name(d.class_name);
  out->set_score(d.score);
  if (d.primitive) {
    const ontology::ShapeFit& f = *d.primitive;
    auto* p = out->mutable_primitive();
    p->set_shape(ontology::to_string(f.shape));
    to_proto(f.center, p->mutable_center());
    to_proto(f.axis, p->mutable_axis());
    to_proto(f.x_axis, p->mutable_x_axis());
    p->set_radius_m(f.radius_m);
    p->set_bottom_radius_m(f.bottom_radius_m);
    p->set_top_radius_m(f.top_radius_m);
    p->set_height_m(f.height_m);
    p->set_size_x_m(f.size_m.x());
    p->set_size_y_m(f.size_m.y());
    p->set_rms_m(f.rms_m);
  }
  for (const auto& g : d.grasps) {
    auto* p = out->add_grasps();
    p->set_name(g.name);
    p->set_kind(ontology::to_string(g.kind));
    to_proto(g.position, p->mutable_position());
    to_proto(g.approach, p->mutable_approach());
    to_proto(g.closing, p->mutable_closing());
    p->set_width_m(g.width_m);
  }
}

}  // namespace scenewatch::service::convert
