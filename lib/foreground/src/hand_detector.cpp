// Placeholder until the skin model lands: no hands found.
#include "scenewatch/foreground/hand_detector.h"

namespace scenewatch::foreground {

Status validate(const HandConfig& c) {
  if (!(c.min_hand_area_m2 > 0 && c.min_hand_area_m2 < c.max_hand_area_m2)) return invalid_argument("foreground.hands.min_area_m2: must be > 0 and below max_area_m2");
  return {};
}

HandDetection detect_hands(const Cloud& organized, const HandConfig&) {
  HandDetection d;
  d.width = static_cast<int>(organized.width);
  d.height = static_cast<int>(organized.height);
  return d;
}

}  // namespace scenewatch::foreground
