#pragma once
// The cameras feeding one working memory (issue 28): each frame names its camera (Frame::camera),
// and what is kept per camera (planes, hand memory, candidates' persistence) is keyed by a small
// id. At most kMaxCameras are followed: a new one beyond that forgets the one seen least recently.
// NOT thread safe: the working memory's writer owns it.
#include <cstdint>
#include <map>
#include <optional>
#include <string>

namespace scenewatch::pipeline {

class CameraRegistry {
 public:
  static constexpr std::size_t kMaxCameras = 64;

  /// The id of a camera name (a new name gets a new id, never one used before). When a camera had
  /// to be forgotten to make room, `forgotten` receives its id.
  std::uint32_t id(const std::string& name, std::optional<std::uint32_t>* forgotten) {
    ++clock_;
    auto it = cameras_.find(name);
    if (it != cameras_.end()) {
      it->second.last_seen = clock_;
      return it->second.id;
    }
    if (cameras_.size() >= kMaxCameras) {
      auto oldest = cameras_.begin();
      for (auto c = cameras_.begin(); c != cameras_.end(); ++c)
        if (c->second.last_seen < oldest->second.last_seen) oldest = c;
      if (forgotten != nullptr) *forgotten = oldest->second.id;
      cameras_.erase(oldest);
    }
    const std::uint32_t id = next_id_++;
    cameras_.emplace(name, Entry{id, clock_});
    return id;
  }

  std::size_t size() const { return cameras_.size(); }
  /// The id of a known camera name.
  std::optional<std::uint32_t> find(const std::string& name) const {
    auto it = cameras_.find(name);
    if (it == cameras_.end()) return std::nullopt;
    return it->second.id;
  }
  /// The name of a followed camera's id ("" for an id not followed, or the unnamed camera).
  std::string name_of(std::uint32_t id) const {
    for (const auto& [name, entry] : cameras_)
      if (entry.id == id) return name;
    return {};
  }
  /// Every followed camera: name and id, by name.
  std::map<std::string, std::uint32_t> names() const {
    std::map<std::string, std::uint32_t> out;
    for (const auto& [name, entry] : cameras_) out[name] = entry.id;
    return out;
  }
  void reset() { cameras_.clear(); }

 private:
  struct Entry {
    std::uint32_t id = 0;
    std::uint64_t last_seen = 0;
  };
  std::map<std::string, Entry> cameras_;
  std::uint32_t next_id_ = 0;
  std::uint64_t clock_ = 0;
};

}  // namespace scenewatch::pipeline
