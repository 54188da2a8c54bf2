// PNG reading and writing through OpenCV's imgcodecs (libpng underneath). OpenCV stays in here.
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cstring>
#include <fstream>
#include <system_error>

#include "scenewatch/core/files.h"
#include "scenewatch/io/image_io.h"

namespace scenewatch::io {
namespace fs = std::filesystem;

namespace {

Result<cv::Mat> read_png(const fs::path& path) {
  if (auto st = check_readable_file(path); !st) return st.error();
  std::error_code ec;
  if (fs::file_size(path, ec) == 0) return invalid_argument(quoted(path) + ": empty file");
  cv::Mat image;
  try {
    image = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    return invalid_argument(quoted(path) + ": cannot decode image: " + e.what());
  }
  if (image.empty()) return invalid_argument(quoted(path) + ": cannot decode image (not a PNG or JPEG, or truncated)");
  return image;
}

Status write_mat(const fs::path& path, const cv::Mat& mat) {
  std::error_code ec;
  if (path.has_parent_path()) fs::create_directories(path.parent_path(), ec);
  try {
    const Status written = with_system_reason([&]() -> Status {
      if (!cv::imwrite(path.string(), mat)) return io_error(quoted(path) + ": cannot write image");
      return {};
    });
    if (!written) return written;
  } catch (const cv::Exception& e) {
    return io_error(quoted(path) + ": cannot write image: " + e.what());
  }
  return {};
}

std::string depth_name(int depth) {
  switch (depth) {
    case CV_8U: return "8-bit";
    case CV_16U: return "16-bit";
    case CV_32F: return "32-bit float";
    default: return "depth code " + std::to_string(depth);
  }
}

Result<cv::Mat> read_single_channel_16(const fs::path& path, const char* what, bool allow_8bit) {
  auto image = read_png(path);
  if (!image) return image.error();
  cv::Mat m = *image;
  if (m.channels() != 1) {
    return invalid_argument(quoted(path) + ": " + what + " PNG must have one channel, it has " +
                            std::to_string(m.channels()));
  }
  if (m.depth() == CV_8U && allow_8bit) {
    cv::Mat converted;
    m.convertTo(converted, CV_16U);
    return converted;
  }
  if (m.depth() != CV_16U) {
    return invalid_argument(quoted(path) + ": " + what + " PNG must be 16-bit, it is " + depth_name(m.depth()));
  }
  return m;
}

template <typename Image, typename T>
Status check_buffer(const fs::path& path, const Image& image, const std::vector<T>& buffer, int channels) {
  if (image.width <= 0 || image.height <= 0) return invalid_argument(quoted(path) + ": image has no pixels");
  const std::size_t expected = static_cast<std::size_t>(image.width) * image.height * channels;
  if (buffer.size() != expected) {
    return invalid_argument(quoted(path) + ": buffer holds " + std::to_string(buffer.size()) + " values, " +
                            std::to_string(image.width) + "x" + std::to_string(image.height) + " needs " +
                            std::to_string(expected));
  }
  return {};
}

// Copies a continuous or padded single-channel 16-bit Mat into a row-major buffer.
void copy_rows(const cv::Mat& m, std::vector<std::uint16_t>& out) {
  out.resize(m.total());
  for (int r = 0; r < m.rows; ++r) {
    std::memcpy(out.data() + static_cast<std::size_t>(r) * m.cols, m.ptr(r), m.cols * sizeof(std::uint16_t));
  }
}

}  // namespace

Result<ColorImage> read_color_png(const fs::path& path) {
  auto image = read_png(path);
  if (!image) return image.error();
  cv::Mat m = *image;
  if (m.depth() == CV_16U) m.convertTo(m, CV_8U, 1.0 / 257.0);
  if (m.depth() != CV_8U) return invalid_argument(quoted(path) + ": colour image must be 8 or 16 bit");
  cv::Mat rgb;
  switch (m.channels()) {
    case 1: cv::cvtColor(m, rgb, cv::COLOR_GRAY2RGB); break;
    case 3: cv::cvtColor(m, rgb, cv::COLOR_BGR2RGB); break;
    case 4: cv::cvtColor(m, rgb, cv::COLOR_BGRA2RGB); break;
    default: return invalid_argument(quoted(path) + ": colour image has " + std::to_string(m.channels()) + " channels");
  }
  ColorImage out;
  out.width = rgb.cols;
  out.height = rgb.rows;
  out.rgb.resize(static_cast<std::size_t>(rgb.total()) * 3);
  for (int r = 0; r < rgb.rows; ++r) {
    std::memcpy(out.rgb.data() + static_cast<std::size_t>(r) * rgb.cols * 3, rgb.ptr(r), rgb.cols * 3);
  }
  return out;
}

Result<DepthImage> read_depth_png(const fs::path& path) {
  auto m = read_single_channel_16(path, "depth", /*allow_8bit=*/false);
  if (!m) return m.error();
  DepthImage out;
  out.width = m->cols;
  out.height = m->rows;
  copy_rows(*m, out.depth_mm);
  return out;
}

Result<LabelImage> read_label_png(const fs::path& path) {
  auto m = read_single_channel_16(path, "label", /*allow_8bit=*/true);
  if (!m) return m.error();
  LabelImage out;
  out.width = m->cols;
  out.height = m->rows;
  copy_rows(*m, out.labels);
  return out;
}

Result<std::pair<int, int>> read_png_size(const fs::path& path) {
  if (auto st = check_readable_file(path); !st) return st.error();
  std::ifstream in(path, std::ios::binary);
  unsigned char head[24];
  in.read(reinterpret_cast<char*>(head), sizeof(head));
  static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (!in || std::memcmp(head, kSignature, 8) != 0 || std::memcmp(head + 12, "IHDR", 4) != 0) {
    return invalid_argument(quoted(path) + ": not a PNG file");
  }
  auto be32 = [&](int at) {
    return static_cast<int>((std::uint32_t{head[at]} << 24) | (std::uint32_t{head[at + 1]} << 16) |
                            (std::uint32_t{head[at + 2]} << 8) | head[at + 3]);
  };
  return std::make_pair(be32(16), be32(20));
}

Status write_color_png(const fs::path& path, const ColorImage& image) {
  if (auto st = check_buffer(path, image, image.rgb, 3); !st) return st;
  cv::Mat rgb(image.height, image.width, CV_8UC3, const_cast<std::uint8_t*>(image.rgb.data()));
  cv::Mat bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  return write_mat(path, bgr);
}

Result<std::string> encode_color_png(const ColorImage& image) {
  if (auto st = check_buffer("(in memory)", image, image.rgb, 3); !st) return st.error();
  cv::Mat rgb(image.height, image.width, CV_8UC3, const_cast<std::uint8_t*>(image.rgb.data()));
  cv::Mat bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  std::vector<std::uint8_t> bytes;
  try {
    if (!cv::imencode(".png", bgr, bytes)) return io_error("cannot encode a " + std::to_string(image.width) + "x" +
                                                           std::to_string(image.height) + " image as PNG");
  } catch (const cv::Exception& e) {
    return io_error(std::string("cannot encode an image as PNG: ") + e.what());
  }
  return std::string(bytes.begin(), bytes.end());
}

Status write_depth_png(const fs::path& path, const DepthImage& image) {
  if (auto st = check_buffer(path, image, image.depth_mm, 1); !st) return st;
  return write_mat(path, cv::Mat(image.height, image.width, CV_16UC1, const_cast<std::uint16_t*>(image.depth_mm.data())));
}

Status write_label_png(const fs::path& path, const LabelImage& image) {
  if (auto st = check_buffer(path, image, image.labels, 1); !st) return st;
  return write_mat(path, cv::Mat(image.height, image.width, CV_16UC1, const_cast<std::uint16_t*>(image.labels.data())));
}

}  // namespace scenewatch::io
