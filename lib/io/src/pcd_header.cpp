#include "pcd_header.h"

#include <fstream>
#include <sstream>

#include "scenewatch/core/files.h"

namespace scenewatch::io {
namespace fs = std::filesystem;

namespace {

constexpr std::size_t kMaxHeaderLines = 64;
constexpr std::size_t kMaxFields = 256;

/// A whole number of at most 18 digits (no sign, no exponent).
bool parse_count(const std::string& word, std::uint64_t& out) {
  if (word.empty() || word.size() > 18 || word.find_first_not_of("0123456789") != std::string::npos) return false;
  out = std::stoull(word);
  return true;
}

/// PCL's header parser does not stop at DATA: it goes on reading lines as header lines while
/// they begin with a keyword (skipping blank lines and comments), so data that happens to begin
/// with "WIDTH 99999999" is taken as header, and PCL sizes the cloud from it before anything can
/// be compared (found by fuzz_pcd: a 42 GB allocation). Such data is refused.
Status check_data_start(std::istream& in, const fs::path& path) {
  static const char* const kKeywords[] = {"VERSION", "FIELDS", "COLUMNS", "SIZE", "TYPE", "COUNT",
                                          "WIDTH", "HEIGHT", "VIEWPOINT", "POINTS", "DATA"};
  constexpr std::size_t kMaxLookahead = 64 * 1024;
  std::string data(kMaxLookahead, '\0');
  in.read(data.data(), static_cast<std::streamsize>(data.size()));
  data.resize(static_cast<std::size_t>(in.gcount()));
  std::istringstream lines(data);
  for (std::string line; std::getline(lines, line);) {
    std::istringstream words(line);
    std::string first;
    if (!(words >> first) || first[0] == '#') continue;  // PCL skips these and reads on
    for (const char* keyword : kKeywords) {
      if (first.rfind(keyword, 0) == 0) {
        return invalid_argument(quoted(path) + ": the data after the DATA line begins like a header line ('" +
                                first.substr(0, 16) + "'), which PCL would read as one");
      }
    }
    return {};
  }
  return {};
}

}  // namespace

Result<PcdHeader> read_pcd_header(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return io_error(quoted(path) + ": cannot open");
  PcdHeader h;
  std::vector<std::string> sizes, types, counts;
  bool have_points = false, have_width = false, have_height = false;
  std::string line;
  std::uint64_t offset = 0;
  for (std::size_t line_no = 1; line_no <= kMaxHeaderLines && std::getline(in, line); ++line_no) {
    offset += line.size() + (in.eof() ? 0 : 1);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::string where = quoted(path) + " header line " + std::to_string(line_no) + ": ";
    std::istringstream words(line);
    std::string key;
    if (!(words >> key) || key[0] == '#') continue;
    std::vector<std::string> values;
    for (std::string w; words >> w;) values.push_back(w);
    auto one_count = [&](std::uint64_t& out) -> Status {
      if (values.size() != 1 || !parse_count(values[0], out)) return invalid_argument(where + key + " must be one whole number");
      return {};
    };
    if (key == "VERSION") {
      continue;
    } else if (key == "FIELDS" || key == "COLUMNS") {
      if (values.empty() || values.size() > kMaxFields) return invalid_argument(where + "FIELDS must name 1 to 256 fields");
      h.fields = values;
    } else if (key == "SIZE") {
      sizes = values;
    } else if (key == "TYPE") {
      types = values;
    } else if (key == "COUNT") {
      counts = values;
    } else if (key == "WIDTH") {
      if (Status s = one_count(h.width); !s) return s.error();
      have_width = true;
    } else if (key == "HEIGHT") {
      if (Status s = one_count(h.height); !s) return s.error();
      have_height = true;
    } else if (key == "POINTS") {
      if (Status s = one_count(h.points); !s) return s.error();
      have_points = true;
    } else if (key == "VIEWPOINT") {
      if (values.size() != 7) return invalid_argument(where + "VIEWPOINT must hold 7 numbers");
    } else if (key == "DATA") {
      if (values.size() != 1) return invalid_argument(where + "DATA must name one of ascii, binary, binary_compressed");
      const std::string& t = values[0];
      h.data_type = t == "ascii" ? 0 : t == "binary" ? 1 : t == "binary_compressed" ? 2 : -1;
      if (h.data_type < 0) return invalid_argument(where + "unknown DATA type '" + t + "'");
      h.data_offset = offset;
      if (Status s = check_data_start(in, path); !s) return s.error();
      break;
    } else {
      return invalid_argument(where + "unknown header keyword '" + key + "'");
    }
  }
  if (h.data_type < 0) return invalid_argument(quoted(path) + ": not a PCD file (no DATA line in its header)");
  if (h.fields.empty()) return invalid_argument(quoted(path) + ": PCD header has no FIELDS line");
  if (counts.empty()) counts.assign(h.fields.size(), "1");
  if (sizes.size() != h.fields.size() || types.size() != h.fields.size() || counts.size() != h.fields.size()) {
    return invalid_argument(quoted(path) + ": PCD header has " + std::to_string(h.fields.size()) +
                            " FIELDS but " + std::to_string(sizes.size()) + " SIZE, " + std::to_string(types.size()) +
                            " TYPE and " + std::to_string(counts.size()) + " COUNT values");
  }
  for (std::size_t i = 0; i < h.fields.size(); ++i) {
    std::uint64_t size = 0, count = 0;
    const bool size_ok = parse_count(sizes[i], size) && (size == 1 || size == 2 || size == 4 || size == 8);
    const bool type_ok = types[i] == "F" ? (size == 4 || size == 8) : (types[i] == "I" || types[i] == "U");
    if (!size_ok || !type_ok || !parse_count(counts[i], count) || count == 0 || count > 1u << 20) {
      return invalid_argument(quoted(path) + ": PCD field '" + h.fields[i] + "' has SIZE '" + sizes[i] + "', TYPE '" +
                              types[i] + "', COUNT '" + counts[i] + "' (SIZE 1, 2, 4 or 8, TYPE I, U or F, COUNT >= 1)");
    }
    h.point_step += size * count;
  }
  if (!have_width || !have_height) return invalid_argument(quoted(path) + ": PCD header lacks WIDTH or HEIGHT");
  if (h.width > (1u << 31) || h.height > (1u << 31)) return invalid_argument(quoted(path) + ": PCD WIDTH or HEIGHT too large");
  if (have_points && h.points != h.width * h.height) {
    return invalid_argument(quoted(path) + ": PCD header says POINTS " + std::to_string(h.points) + " but WIDTH x HEIGHT = " +
                            std::to_string(h.width * h.height));
  }
  h.points = h.width * h.height;
  return h;
}

}  // namespace scenewatch::io
