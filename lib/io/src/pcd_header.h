#pragma once
// A strict reading of a PCD header, made before PCL's: PCL's own header parser accepts malformed
// lines (a SIZE of '.', a second FIELDS line after DATA) and then reads past its buffers; what it
// makes of such a header is compared against this one and refused when they differ.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "scenewatch/core/result.h"

namespace scenewatch::io {

/// What a well-formed PCD header says (format 0.7, or 0.6 and older without VIEWPOINT/COUNT).
struct PcdHeader {
  std::vector<std::string> fields;
  std::uint64_t point_step = 0;   ///< bytes of one point: sum of SIZE x COUNT
  std::uint64_t width = 0, height = 0, points = 0;
  int data_type = -1;             ///< 0 ascii, 1 binary, 2 binary_compressed (PCL's numbering)
  std::uint64_t data_offset = 0;  ///< first byte after the DATA line
};

/// Reads the header lines up to and including DATA. Errors name the file, the line and the
/// problem: an unknown keyword, a SIZE/TYPE/COUNT list that does not match FIELDS, a SIZE that is
/// not 1, 2, 4 or 8 (8 only for F, I or U), WIDTH x HEIGHT != POINTS, an unknown DATA type.
Result<PcdHeader> read_pcd_header(const std::filesystem::path& path);

}  // namespace scenewatch::io
