#pragma once
/// What one depth measurement is worth: the noise of a depth camera against range and incidence,
/// which of its pixels can be trusted at all, and how well the pose given with a frame is known.
/// Every piece of change evidence is measured against it instead of against constants tuned on one
/// recording (issue 28).
///
/// Profiles (`sensor.profile`):
/// - `structured_light` (default): Kinect v1, Asus Xtion, PrimeSense (7-Scenes, mOSD, hrt1, YCB-Video).
///   Axial noise sigma_z = 0.0012 + 0.0019 (z - 0.4)^2 m, lateral noise 0.8 px, both growing at
///   grazing incidence (Nguyen, Izadi & Lovell, 3DIMPVT 2012, eqs. 2-3). It agrees with
///   Khoshelham & Elberink (Sensors 2012): about 1.4 mm x z^2, 4 cm at 5 m. Depth at a depth edge is
///   smeared by its 9x9 correlation window (Konolige & Mihelich, "Technical description of Kinect
///   calibration", ROS wiki), so the image's outer 8 px carry no evidence.
/// - `active_stereo`: Intel RealSense D400. RMS error = z^2 x subpixel / (f x baseline), subpixel
///   about 0.08 (Grunnet-Jepsen et al., "Tuning depth cameras for best performance", Intel white
///   paper): a D435 at 640x480 (f about 340 px, baseline 50 mm) gives 4.7 mm x z^2. Its lateral
///   noise (1 px) is this project's assumption, not a measured figure.
/// - `time_of_flight`: Kinect v2 / Azure Kinect. sigma_z = 1.5 - 0.5 z + 0.3 z^2 mm on the axis
///   (Fankhauser et al., "Kinect v2 for mobile robot navigation: evaluation and modeling", ICAR
///   2015), written here as 1.29 mm + 0.3 mm (z - 0.83)^2. Lateral noise 1.5 px, for flying pixels
///   wider than structured light's, is an assumption, not a measured figure.
/// - `explicit`: the coefficients as written in the config, nothing filled in.
#include <string>

#include "scenewatch/core/result.h"

namespace scenewatch {

struct SensorModel {
  std::string profile = "structured_light";
  /// Axial noise: sigma_z(z) = axial_base_m + axial_quad_per_m (z - axial_offset_m)^2 (Nguyen 2012).
  double axial_base_m = 0.0012;
  double axial_quad_per_m = 0.0019;
  double axial_offset_m = 0.4;
  /// Lateral noise of a pixel's position, pixels (Nguyen 2012: 0.8 px below 60 degrees incidence).
  /// Pixels within sigma_factor times this of a depth edge or a hole carry no evidence for what
  /// they show (flying pixels between two surfaces, a shadow's or a reflection's rim).
  double lateral_px = 0.8;
  /// Depths outside [min_range_m, max_range_m] are not measurements (the sensor's working range).
  double min_range_m = 0.4;
  double max_range_m = 4.5;
  /// Pixels this close to the image border carry no evidence: the lens' distortion is largest
  /// there, and a structured-light sensor's correlation window runs off the image.
  int border_px = 8;
  /// Misregistration between colour and depth, pixels: colour at a depth edge may belong to the
  /// other side. 7-Scenes' colour and depth are known not to be registered exactly.
  double registration_px = 2.0;
  /// Measure each camera's colour-to-depth registration from its first frames (depth contours
  /// against colour edges, core/colour_registration.h) and lay the colour onto the depth before
  /// anything reads it. A raw Kinect v1 recording's colour lies 10 % nearer the image centre and
  /// some pixels aside (7-Scenes); a driver-registered one within a few pixels.
  bool fit_colour_registration = true;
  /// How well the pose given with a frame is known, 1 sigma: the pose source's accuracy, where
  /// it is known (motion capture: 1 mm; an arm's kinematics; a SLAM system's). The change
  /// detector also measures each frame's misalignment against the map and takes the larger
  /// (change::pose_agreement), so 0, the default, means "as good as each frame shows".
  double pose_sigma_m = 0.0;
  double pose_sigma_deg = 0.0;

  /// Axial noise at depth z for a surface seen head-on, metres. Inline: the alignment asks it
  /// twice a pixel.
  double sigma_z(double z_m) const {
    const double d = z_m - axial_offset_m;
    return axial_base_m + axial_quad_per_m * d * d;
  }
  /// ... and at an incidence angle (radians from the ray) up to 89 degrees: Nguyen's eq. (2),
  /// the angle term scaled to this profile's axial noise.
  double sigma_z(double z_m, double incidence_rad) const;
  /// Lateral noise at an incidence angle, pixels (Nguyen's eq. (3)).
  double lateral_sigma_px(double incidence_rad) const;
  /// How far along its ray a pixel's point may lie from where its surface crosses that ray, metres:
  /// the axial noise at that incidence, and the lateral noise, which on a surface inclined at the
  /// incidence moves the depth by lateral_sigma_px z / f tan(incidence).
  double sigma_along_ray(double z_m, double incidence_rad, double focal_px) const;
  /// The uncertainty of a world position placed with the given pose at range z, metres:
  /// translation plus the rotation's arc, 1 sigma.
  double pose_sigma_at(double range_m) const;
  /// ... and of its pixel, pixels, for focal length f.
  double pose_sigma_px(double range_m, double focal_px) const;
  /// The band around depth edges and holes whose pixels are no evidence: sigma_factor lateral
  /// noises, rounded up (structured light at 3 sigma: 3 px).
  int edge_band_px(double sigma_factor) const;
  /// True when a depth lies in the working range.
  bool in_range(double z_m) const { return z_m >= min_range_m && z_m <= max_range_m; }
};

/// The named profile's defaults; an error naming the known profiles for any other name.
Result<SensorModel> sensor_profile(const std::string& name);

/// Validates ranges; the message names the key ("sensor.axial_base_m: ...").
Status validate(const SensorModel& sensor);

}  // namespace scenewatch
