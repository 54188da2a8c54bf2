// Commands on the daemon's object classes (its ontology): list them, add or replace some.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>

#include "commands.h"
#include "remote_client.h"
#include "subcommand.h"

namespace scenewatch::cli {
using nlohmann::json;

int run_classes(const RemoteOptions& options) {
  proto::Request request;
  request.mutable_list_classes();
  return simple_call(options, request, [&](const proto::Response& r) {
    const auto& reply = r.list_classes();
    if (options.json) {
      json classes = json::array();
      for (const auto& c : reply.classes()) {
        json grasps = json::array();
        for (const auto& g : c.grasps()) grasps.push_back({{"name", g.name()}, {"kind", g.kind()}, {"height_fraction", g.height_fraction()}});
        json j = {{"name", c.name()}, {"shape", c.shape()}, {"axis", c.axis()}, {"top", c.top()}, {"grasps", grasps},
                  {"allowed_dofs", std::vector<std::string>(c.allowed_dofs().begin(), c.allowed_dofs().end())},
                  {"defined_dofs", std::vector<std::string>(c.defined_dofs().begin(), c.defined_dofs().end())},
                  {"learnt_free_dofs", std::vector<std::string>(c.learnt_free_dofs().begin(), c.learnt_free_dofs().end())},
                  {"learnt_frozen_dofs", std::vector<std::string>(c.learnt_frozen_dofs().begin(), c.learnt_frozen_dofs().end())}};
        if (c.has_radius_m()) j["radius_m"] = {c.radius_m().min(), c.radius_m().max()};
        if (c.has_height_m()) j["height_m"] = {c.height_m().min(), c.height_m().max()};
        if (c.has_taper_deg()) j["taper_deg"] = {c.taper_deg().min(), c.taper_deg().max()};
        json sizes = json::array();
        for (const auto& range : c.size_m()) sizes.push_back({range.min(), range.max()});
        if (!sizes.empty()) j["size_m"] = sizes;
        classes.push_back(std::move(j));
      }
      return print_json({{"classes", classes}});
    }
    std::cout << reply.classes_size() << (reply.classes_size() == 1 ? " class" : " classes") << "\n";
    auto mm = [](const proto::Range& range) {
      return std::to_string(static_cast<int>(std::lround(range.min() * 1000))) + ".." +
             std::to_string(static_cast<int>(std::lround(range.max() * 1000))) + " mm";
    };
    for (const auto& c : reply.classes()) {
      std::cout << "  " << c.name() << ": " << c.shape();
      if (c.has_radius_m()) std::cout << ", radius " << mm(c.radius_m());
      if (c.has_height_m()) std::cout << ", height " << mm(c.height_m());
      for (int i = 0; i < c.size_m_size(); ++i) std::cout << (i == 0 ? ", sides " : " x ") << mm(c.size_m(i));
      std::cout << ", axis " << c.axis() << ", top " << c.top() << "; grasps";
      for (const auto& g : c.grasps()) std::cout << " " << g.name() << " (" << g.kind() << ")";
      // Allowed motions: those defined (config, DefineClass), then those only learnt from handled
      // instances, then what handling never moved.
      std::cout << "; motions";
      for (const auto& d : c.defined_dofs()) std::cout << " " << d;
      std::cout << (c.defined_dofs_size() == 0 ? " none defined" : " (defined)");
      std::string learnt_only;
      for (const auto& d : c.learnt_free_dofs())
        if (std::find(c.defined_dofs().begin(), c.defined_dofs().end(), d) == c.defined_dofs().end()) learnt_only += " " + d;
      if (!learnt_only.empty()) std::cout << " +" << learnt_only << " (learnt)";
      if (c.learnt_free_dofs_size() + c.learnt_frozen_dofs_size() > 0) {
        std::cout << "; learnt from handling: free";
        for (const auto& d : c.learnt_free_dofs()) std::cout << " " << d;
        std::cout << ", frozen";
        for (const auto& d : c.learnt_frozen_dofs()) std::cout << " " << d;
        if (c.learnt_frozen_dofs_size() == 0) std::cout << " none";
      }
      std::cout << "\n";
    }
    std::cout << std::flush;
  });
}

int run_define_class(const RemoteOptions& options, const std::string& yaml_file) {
  std::ifstream in(yaml_file);
  if (!in) return fail(yaml_file + ": cannot open the classes file");
  std::stringstream text;
  text << in.rdbuf();
  proto::Request request;
  request.mutable_define_class()->set_yaml(text.str());
  return simple_call(options, request, [&](const proto::Response& r) {
    const auto& reply = r.define_class();
    const std::vector<std::string> names(reply.defined().begin(), reply.defined().end());
    if (options.json) return print_json({{"defined", names}, {"persisted", reply.persisted()}});
    std::cout << "defined";
    for (const auto& n : names) std::cout << " " << n;
    std::cout << (reply.persisted() ? " (stored in the daemon's ontology.sqlite)" : " (the daemon has no model directory: until it stops)")
              << std::endl;
  });
}

void add_class_commands(CLI::App& app, RemoteOptions& remote, Action& action) {
  add_daemon_command(app, "classes", "list the daemon's object classes (name, primitive, bounds, grasps)", remote, action,
                     run_classes);

  auto class_file = std::make_shared<std::string>();
  auto* define_class = app.add_subcommand(
      "define-class", "add or replace object classes from FILE (config/ontology.yaml's format); kept in the daemon's ontology.sqlite");
  define_class->add_option("file", *class_file, "YAML file: classes: [...]")->required();
  add_remote_options(define_class, remote);
  on_parsed(define_class, action, [&remote, class_file] { return run_define_class(remote, *class_file); });
}

}  // namespace scenewatch::cli
