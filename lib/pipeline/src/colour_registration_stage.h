#pragma once
// Each camera's colour laid onto its depth (issue 28's sensor model, core/colour_registration.h):
// measured on the camera's first frame with depth contours, then applied to every frame before anything reads its
// colour (the tracker's photometric term, the keyframes and the mesh's texture, the image
// surprise, the hand detector). A registration that moves no pixel by a whole pixel is left
// alone: the frame goes on as it came, uncopied.
// NOT thread safe: the working memory's writer owns it.
#include <cstdint>
#include <map>
#include <memory>

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
    Frame out = frame;
    out.cloud = c.remap->apply(*frame.cloud);
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
  SensorModel sensor_;
  struct Camera {
    ColourRegistrationEstimate estimate;
    std::unique_ptr<ColourRemap> remap;  // laid out for the camera's image size at its first registered frame
  };
  std::map<std::uint32_t, Camera> cameras_;
};

}  // namespace scenewatch::pipeline
