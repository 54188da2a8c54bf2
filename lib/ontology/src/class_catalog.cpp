#include "scenewatch/ontology/class_catalog.h"

namespace scenewatch::ontology {

Result<std::unique_ptr<ClassCatalog>> ClassCatalog::open(const std::filesystem::path& classes_file,
                                                         const std::filesystem::path& store_path) {
  std::unique_ptr<ClassCatalog> catalog(new ClassCatalog());
  if (!classes_file.empty()) {
    auto loaded = load_classes_file(classes_file);
    if (!loaded) return loaded.error();
    catalog->library_ = std::move(*loaded);
  }
  if (!store_path.empty()) {
    auto store = ClassStore::open(store_path);
    if (!store) return store.error();
    auto stored = store->classes();
    if (!stored) return stored.error();
    for (const auto& c : *stored) {
      if (Status s = catalog->library_.define(c); !s) return Error{s.error().code, store_path.string() + ": " + s.error().message};
    }
    catalog->store_.emplace(std::move(*store));
  }
  return catalog;
}

Status ClassCatalog::define(const ObjectClass& object_class, double time_s) {
  if (Status s = validate(object_class); !s) return s;
  std::lock_guard<std::mutex> lock(mutex_);
  if (store_) {
    if (Status s = store_->put_class(object_class, time_s); !s) return s;
  }
  return library_.define(object_class);
}

ClassLibrary ClassCatalog::library() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return library_;
}

bool ClassCatalog::persistent() const { return store_.has_value(); }

}  // namespace scenewatch::ontology
