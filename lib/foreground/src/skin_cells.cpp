// The hand detector's skin on its grid (skin_cells.h): the skin model's mask, closed and dilated.
#include "skin_cells.h"

#include <opencv2/imgproc.hpp>

#include "skin_model.h"

namespace scenewatch::foreground {

SkinCells find_skin_cells(const Grid& g, int skin_dilation_px) {
  // Closing bridges one-cell gaps in the mask: a dark forearm in shadow breaks into pieces
  // where single pixels fall below the luminance gate. Dilating then tolerates colour and depth
  // that are not quite registered (hrt1's are ~15 px apart at the image's side): the skin's
  // depth lies beside its colour. The components are depth-continuous, so the dilated mask does
  // not join the background.
  SkinCells s;
  const std::size_t n = g.p.size();
  s.mask = skin_mask(g.rgb, g.w, g.h);
  s.colour = s.mask;  // before closing and dilation
  s.dilation_radius = (skin_dilation_px + g.step - 1) / g.step;
  {
    cv::Mat mask(g.h, g.w, CV_8U, s.mask.data());
    cv::morphologyEx(mask, mask, cv::MORPH_CLOSE, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3)));
    if (s.dilation_radius > 0) {
      cv::dilate(mask, mask, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * s.dilation_radius + 1, 2 * s.dilation_radius + 1)));
    }
  }
  s.luma.resize(n);
  for (std::size_t c = 0; c < n; ++c) s.luma[c] = 0.299f * g.rgb[3 * c] + 0.587f * g.rgb[3 * c + 1] + 0.114f * g.rgb[3 * c + 2] + 1.0f;
  return s;
}

}  // namespace scenewatch::foreground
