#pragma once
/// A camera's change of localization state, announced to subscribers (issue 29): when a frame
/// leaves its camera in another state (given, starting, tracking, lost) or homed where it was not,
/// every connection that subscribed gets a Response with id 0 whose `localization` holds that
/// camera's LocalizationResult, interleaved with the pushed events. A camera's first frame is a
/// change unless its state is `given` (a camera whose poses are trusted has nothing to announce).
/// Thread safe. Private to the service.
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <string>

#include "scenewatch/localization/localizer.h"

namespace scenewatch::service {

class LocalizationNotices {
 public:
  /// Takes a serialized Response (the connection's event sink).
  using Sink = std::function<void(std::string)>;

  /// A subscribed connection, by its subscription token; remove() when it unsubscribes.
  void add(int token, Sink sink);
  void remove(int token);

  /// After a frame of `camera` ("": the default camera) was processed: pushes its localization to
  /// every sink when the camera's state or homing changed since its last frame.
  void after_frame(const std::string& camera, const localization::Localization& where);

  /// The model was reset or loaded: every camera starts anew.
  void forget_cameras();

  /// How many cameras are remembered at most; beyond, the one heard from longest ago is forgotten
  /// (the working memory keeps 64 cameras apart).
  static constexpr std::size_t kMaxCameras = 64;

 private:
  struct Last {
    localization::State state = localization::State::kGiven;
    bool homed = false;
    std::uint64_t heard = 0;
  };
  std::mutex mutex_;
  std::map<int, Sink> sinks_;
  std::map<std::string, Last> cameras_;
  std::uint64_t frames_ = 0;
};

}  // namespace scenewatch::service
