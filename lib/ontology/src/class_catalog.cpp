#include "scenewatch/ontology/class_catalog.h"

#include <utility>

namespace scenewatch::ontology {

std::vector<std::string> LearntMotions::names(bool free_ones) const {
  std::vector<std::string> out;
  for (int k = 0; k < kDofCount; ++k)
    if (free[static_cast<std::size_t>(k)] == free_ones) out.emplace_back(to_string(static_cast<Dof>(k)));
  return out;
}

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
    auto constraints = store->constraints();
    if (!constraints) return constraints.error();
    for (const auto& c : *constraints) {
      LearntMotions& learnt = catalog->learnt_[c.class_name];
      for (int k = 0; k < kDofCount; ++k)
        if (c.dof == to_string(static_cast<Dof>(k))) learnt.free[static_cast<std::size_t>(k)] = c.allowed;
    }
    catalog->store_.emplace(std::move(*store));
    catalog->writer_ = std::thread([c = catalog.get()] { c->write_loop(); });
  }
  return catalog;
}

ClassCatalog::~ClassCatalog() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_writer_.notify_all();
  if (writer_.joinable()) writer_.join();
}

Status ClassCatalog::define(const ObjectClass& object_class, double time_s) {
  if (Status s = validate(object_class); !s) return s;
  std::lock_guard<std::mutex> lock(mutex_);
  if (store_) {
    std::lock_guard<std::mutex> store_lock(store_mutex_);
    if (Status s = store_->put_class(object_class, time_s); !s) return s;
  }
  return library_.define(object_class);
}

ClassLibrary ClassCatalog::library() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return library_;
}

bool ClassCatalog::persistent() const { return store_.has_value(); }

void ClassCatalog::record(const InstanceRecord& instance, const std::optional<DofFlags>& handled_free) {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<ConstraintRecord> changed;
  if (handled_free && instance.class_name != "unknown") {
    const bool first = learnt_.count(instance.class_name) == 0;
    LearntMotions& learnt = learnt_[instance.class_name];
    for (int k = 0; k < kDofCount; ++k) {
      const auto ks = static_cast<std::size_t>(k);
      const bool free = learnt.free[ks] || (*handled_free)[ks];
      // The first handled instance writes all six (frozen ones too: they were seen); later ones
      // only what they free.
      if (first || free != learnt.free[ks]) changed.push_back({instance.class_name, to_string(static_cast<Dof>(k)), free, instance.time_s});
      learnt.free[ks] = free;
    }
  }
  if (!store_) return;
  queued_instances_.push_back(instance);
  queued_constraints_.insert(queued_constraints_.end(), changed.begin(), changed.end());
  ++queued_batches_;
  wake_writer_.notify_one();
}

std::map<std::string, LearntMotions> ClassCatalog::learnt() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return learnt_;
}

Status ClassCatalog::flush() {
  std::unique_lock<std::mutex> lock(mutex_);
  const std::uint64_t target = queued_batches_;
  written_.wait(lock, [&] { return written_batches_ >= target || !writer_.joinable(); });
  std::optional<Error> error = std::move(write_error_);
  write_error_.reset();
  if (error) return *error;
  return {};
}

void ClassCatalog::write_loop() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_writer_.wait(lock, [&] { return stopping_ || queued_batches_ > written_batches_; });
    if (queued_batches_ == written_batches_) {
      if (stopping_) return;
      continue;
    }
    // Everything queued so far, as one batch: instances in one transaction, then the constraints.
    std::vector<InstanceRecord> instances = std::move(queued_instances_);
    std::vector<ConstraintRecord> constraints = std::move(queued_constraints_);
    queued_instances_.clear();
    queued_constraints_.clear();
    const std::uint64_t batches = queued_batches_;
    lock.unlock();
    Status status;
    {
      std::lock_guard<std::mutex> store_lock(store_mutex_);
      if (!instances.empty()) status = store_->add_instances(instances);
      for (const auto& c : constraints) {
        if (!status) break;
        status = store_->put_constraint(c);
      }
    }
    lock.lock();
    if (!status && !write_error_) write_error_ = status.error();
    written_batches_ = batches;
    written_.notify_all();
  }
}

}  // namespace scenewatch::ontology
