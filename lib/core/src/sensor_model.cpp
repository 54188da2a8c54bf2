#include "scenewatch/core/sensor_model.h"

#include <algorithm>
#include <cmath>

namespace scenewatch {
namespace {

// Incidence is capped here: the angle terms of Nguyen's model diverge at 90 degrees.
constexpr double kMaxIncidenceRad = 89.0 * M_PI / 180.0;

// Nguyen, Izadi & Lovell 2012, eq. (2): the Kinect's axial noise, head-on, and its angle term.
double nguyen_axial_m(double z) { return 0.0012 + 0.0019 * (z - 0.4) * (z - 0.4); }
double nguyen_angle_term_m(double z, double theta) {
  const double t = theta / (M_PI / 2 - theta);
  return 0.0001 / std::sqrt(std::max(z, 0.1)) * t * t;
}

}  // namespace

double SensorModel::sigma_z(double z, double incidence_rad) const {
  const double theta = std::clamp(incidence_rad, 0.0, kMaxIncidenceRad);
  const double head_on = sigma_z(z);
  return head_on + nguyen_angle_term_m(z, theta) * head_on / nguyen_axial_m(z);
}

double SensorModel::lateral_sigma_px(double incidence_rad) const {
  const double theta = std::clamp(incidence_rad, 0.0, kMaxIncidenceRad);
  // Nguyen 2012, eq. (3): 0.8 + 0.035 theta / (pi/2 - theta) px, scaled to this profile.
  return lateral_px * (1.0 + 0.035 / 0.8 * theta / (M_PI / 2 - theta));
}

double SensorModel::sigma_along_ray(double z, double incidence_rad, double focal_px) const {
  const double theta = std::clamp(incidence_rad, 0.0, kMaxIncidenceRad);
  const double slope = lateral_sigma_px(theta) * z / std::max(focal_px, 1.0) * std::tan(theta);
  return std::hypot(sigma_z(z, theta), slope);
}

int SensorModel::edge_band_px(double sigma_factor) const { return static_cast<int>(std::ceil(sigma_factor * lateral_px - 1e-9)); }

double SensorModel::pose_sigma_at(double range_m) const {
  const double arc = range_m * pose_sigma_deg * M_PI / 180.0;
  return std::sqrt(pose_sigma_m * pose_sigma_m + arc * arc);
}

double SensorModel::pose_sigma_px(double range_m, double focal_px) const {
  return focal_px * pose_sigma_at(range_m) / std::max(range_m, 0.1);
}

Result<SensorModel> sensor_profile(const std::string& name) {
  SensorModel s;
  s.profile = name;
  if (name == "structured_light" || name == "explicit") return s;
  if (name == "active_stereo") {
    s.axial_base_m = 0.0;
    s.axial_quad_per_m = 0.0047;
    s.axial_offset_m = 0.0;
    s.lateral_px = 1.0;
    s.min_range_m = 0.2;
    s.max_range_m = 6.0;
    return s;
  }
  if (name == "time_of_flight") {
    s.axial_base_m = 0.00129;
    s.axial_quad_per_m = 0.0003;
    s.axial_offset_m = 0.83;
    s.lateral_px = 1.5;
    s.min_range_m = 0.5;
    s.max_range_m = 4.5;
    s.registration_px = 1.0;
    return s;
  }
  return invalid_argument("sensor.profile: unknown profile '" + name +
                          "' (known: structured_light, active_stereo, time_of_flight, explicit)");
}

Status validate(const SensorModel& s) {
  auto bad = [](const std::string& key, const std::string& why) { return invalid_argument("sensor." + key + ": " + why); };
  if (!(s.axial_base_m >= 0 && s.axial_base_m <= 0.1)) return bad("axial_base_m", "must be in [0, 0.1] m");
  if (!(s.axial_quad_per_m >= 0 && s.axial_quad_per_m <= 0.1)) return bad("axial_quad_per_m", "must be in [0, 0.1] 1/m");
  if (!(s.axial_offset_m >= 0 && s.axial_offset_m <= 5)) return bad("axial_offset_m", "must be in [0, 5] m");
  if (!(s.axial_base_m + s.axial_quad_per_m > 0)) return bad("axial_base_m", "axial noise must not be zero everywhere");
  if (!(s.lateral_px >= 0 && s.lateral_px <= 20)) return bad("lateral_px", "must be in [0, 20] px");
  if (!(s.min_range_m >= 0 && s.min_range_m < s.max_range_m)) return bad("min_range_m", "must be >= 0 and below max_range_m");
  if (!(s.max_range_m <= 100)) return bad("max_range_m", "must be at most 100 m");
  if (s.border_px < 0 || s.border_px > 100) return bad("border_px", "must be in [0, 100] px");
  if (!(s.registration_px >= 0 && s.registration_px <= 20)) return bad("registration_px", "must be in [0, 20] px");
  if (!(s.pose_sigma_m >= 0 && s.pose_sigma_m <= 1)) return bad("pose_sigma_m", "must be in [0, 1] m");
  if (!(s.pose_sigma_deg >= 0 && s.pose_sigma_deg <= 10)) return bad("pose_sigma_deg", "must be in [0, 10] degrees");
  return {};
}

}  // namespace scenewatch
