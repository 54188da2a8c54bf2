#include "localization_notices.h"

#include <vector>

#include "proto_convert.h"
#include "scenewatch.pb.h"

namespace scenewatch::service {

void LocalizationNotices::add(int token, Sink sink) {
  std::lock_guard<std::mutex> lock(mutex_);
  sinks_[token] = std::move(sink);
}

void LocalizationNotices::remove(int token) {
  std::lock_guard<std::mutex> lock(mutex_);
  sinks_.erase(token);
}

void LocalizationNotices::forget_cameras() {
  std::lock_guard<std::mutex> lock(mutex_);
  cameras_.clear();
}

void LocalizationNotices::after_frame(const std::string& camera, const localization::Localization& where) {
  std::vector<Sink> sinks;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++frames_;
    auto it = cameras_.find(camera);
    const bool known = it != cameras_.end();
    const bool changed = known ? (it->second.state != where.state || it->second.homed != where.homed)
                               : where.state != localization::State::kGiven;
    if (!known) {
      if (cameras_.size() >= kMaxCameras) {
        auto oldest = cameras_.begin();
        for (auto c = cameras_.begin(); c != cameras_.end(); ++c)
          if (c->second.heard < oldest->second.heard) oldest = c;
        cameras_.erase(oldest);
      }
      it = cameras_.emplace(camera, Last{}).first;
    }
    it->second = Last{where.state, where.homed, frames_};
    if (!changed || sinks_.empty()) return;
    for (const auto& [token, sink] : sinks_) sinks.push_back(sink);
  }
  proto::Response pushed;
  pushed.set_id(0);
  auto* result = pushed.mutable_localization()->add_cameras();
  convert::to_proto(where, result);
  result->set_camera(camera);
  std::string bytes;
  pushed.SerializeToString(&bytes);
  for (const auto& sink : sinks) sink(bytes);
}

}  // namespace scenewatch::service
