#pragma once
// Each camera's colour laid onto its depth (issue 28's sensor model, core/colour_registration.h):
// measured on the camera's first frame with depth contours, then applied to every frame before anything reads its
// colour (the tracker's photometric term, the keyframes and the mesh's texture, the image
// surprise, the hand detector). A registration that moves no pixel by a whole pixel is left
// alone: the frame goes on as it came, uncopied.
// NOT thread safe: the working memory's writer owns it.
#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <vector>

#include "scenewatch/core/colour_registration.h"
#include "scenewatch/core/frame.h"

namespace scenewatch::pipeline {

class ColourRegistrationStage {
 public:
  explicit ColourRegistrationStage(const SensorModel& sensor) : sensor_(sensor) {}

  /// The frame with its colour registered, once its camera's frames have shown how.
  Frame registered(const Frame& frame, std::uint32_t camera) {
    if (!sensor_.fit_colour_registration || !frame.has_color || !frame.cloud || frame.cloud->height < 2) return frame;
    const Intrinsics K = frame.intrinsics.value_or(Intrinsics{});
    Camera& c = cameras_[camera];
    const auto r = c.estimate.update(*frame.cloud, K, sensor_);
    const int w = static_cast<int>(frame.cloud->width), h = static_cast<int>(frame.cloud->height);
    const double cx = K.fx > 0 ? K.cx : (w - 1) / 2.0, cy = K.fy > 0 ? K.cy : (h - 1) / 2.0;
    if (!r || r->max_displacement_px(w, h, cx, cy) < 1.0) return frame;
    if (!c.remap || !c.remap->fits(*frame.cloud)) c.remap = std::make_unique<ColourRemap>(w, h, K, *r);
    CloudPtr registered = spare(c);
    c.remap->apply(*frame.cloud, *registered);
    Frame out = frame;
    out.cloud = std::move(registered);
    return out;
  }

  /// What each camera's frames have shown so far.
  std::map<std::uint32_t, ColourRegistration> measured() const {
    std::map<std::uint32_t, ColourRegistration> out;
    for (const auto& [camera, c] : cameras_)
      if (auto r = c.estimate.current()) out[camera] = *r;
    return out;
  }
  void forget_camera(std::uint32_t camera) { cameras_.erase(camera); }
  void reset() { cameras_.clear(); }

 private:
  // Registered clouds are written into buffers nobody holds any more (a frame's cloud is let go
  // once the frame is processed, unless a stage keeps it), rather than into a fresh 10 MB a frame
  // faulted in page by page. On redkitchen_long two buffers take turns: 2 allocated, then 19 of
  // 21 frames reused one.
  static constexpr std::size_t kBuffers = 3;

  SensorModel sensor_;
  struct Camera {
    ColourRegistrationEstimate estimate;
    std::unique_ptr<ColourRemap> remap;  // laid out for the camera's image size at its first registered frame
    std::vector<CloudPtr> buffers;       // held here alone when use_count() is 1: free to overwrite
  };
  static CloudPtr spare(Camera& c) {
    for (const CloudPtr& b : c.buffers)
      if (b.use_count() == 1) {
        // Whoever let go last is done reading it (its release of the count pairs with this).
        std::atomic_thread_fence(std::memory_order_acquire);
        return b;
      }
    auto b = std::make_shared<Cloud>();
    if (c.buffers.size() < kBuffers) c.buffers.push_back(b);
    return b;
  }
  std::map<std::uint32_t, Camera> cameras_;
};

}  // namespace scenewatch::pipeline
