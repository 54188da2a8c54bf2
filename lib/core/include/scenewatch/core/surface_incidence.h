#pragma once
/// The angle at which a pixel's ray meets the surface it measured, from the depth image around it
/// (issue 28). A surface seen at a grazing angle is a weak witness: the sensor's noise grows there
/// (Nguyen, Izadi & Lovell 2012), and the free space in front of it was carved by rays that ran
/// along it, so the map knows that space only coarsely.
#include <vector>

#include "scenewatch/core/geometry.h"
#include "scenewatch/core/sensor_model.h"

namespace scenewatch {

/// The window half-width, pixels, over which a plane through a pixel at depth z is fitted: wide
/// enough that the depth noise across it (sigma_factor sigma_z) stays within one pixel's lateral
/// footprint per pixel of baseline, at least 2 and at most 8.
int incidence_window_px(const SensorModel& sensor, double z_m, double focal_px, double sigma_factor);

/// The incidence (radians from the ray, 0 = head-on) of the surface at pixel (u, v) of a depth
/// image (row-major, metres, NaN or <= 0 where none) seen with K. A plane is fitted (principal
/// axes) to the window's pixels that lie on the same surface as the centre, by the depth-edge rule
/// of depth_validity.h. NaN when the pixel has no depth or the window too few surface pixels.
double surface_incidence_rad(const std::vector<float>& z_m, const Intrinsics& K, int u, int v,
                             const SensorModel& sensor, double sigma_factor);

}  // namespace scenewatch
