// PCD and PLY reading through PCL's readers, with checks of our own before and after so that a bad
// file gets a message naming the file and the problem instead of PCL's console output.
#include <pcl/PCLPointCloud2.h>
#include <pcl/common/io.h>
#include <pcl/console/print.h>
#include <pcl/conversions.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <limits>
#include <mutex>
#include <sstream>
#include <system_error>

#include "scenewatch/core/files.h"
#include "scenewatch/io/cloud_io.h"

#include "pcd_header.h"

namespace scenewatch::io {
namespace fs = std::filesystem;

namespace {

// PCL reports through its console; we report through Result. Silence it once.
void quiet_pcl() {
  static std::once_flag once;
  std::call_once(once, [] { pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS); });
}

const pcl::PCLPointField* find_field(const pcl::PCLPointCloud2& cloud, const std::string& name) {
  for (const auto& f : cloud.fields) {
    if (f.name == name) return &f;
  }
  return nullptr;
}

// Checks the data section against the header before PCL reads it: PCL's own checks vary by format
// and version, and some truncations would otherwise be read as garbage.
Status check_pcd_body(const fs::path& path, const pcl::PCLPointCloud2& header, int data_type,
                      unsigned int data_idx) {
  const std::uint64_t file_size = fs::file_size(path);
  const std::uint64_t points = static_cast<std::uint64_t>(header.width) * header.height;
  const std::uint64_t body_bytes = points * header.point_step;
  if (data_type == 1) {  // binary
    if (data_idx + body_bytes > file_size) {
      return invalid_argument(quoted(path) + ": truncated binary PCD: header declares " + std::to_string(points) +
                              " points of " + std::to_string(header.point_step) + " bytes (" +
                              std::to_string(body_bytes) + " bytes of data) but the file holds only " +
                              std::to_string(file_size - std::min<std::uint64_t>(file_size, data_idx)));
    }
  } else if (data_type == 2) {  // binary_compressed: two uint32 sizes, then LZF data
    if (data_idx + 8 > file_size) return invalid_argument(quoted(path) + ": truncated compressed PCD: no size header");
    std::ifstream in(path, std::ios::binary);
    in.seekg(data_idx);
    std::uint32_t sizes[2] = {0, 0};
    in.read(reinterpret_cast<char*>(sizes), sizeof(sizes));
    if (!in) return invalid_argument(quoted(path) + ": truncated compressed PCD: cannot read size header");
    if (data_idx + 8ull + sizes[0] > file_size) {
      return invalid_argument(quoted(path) + ": truncated compressed PCD: " + std::to_string(sizes[0]) +
                              " compressed bytes declared, " + std::to_string(file_size - data_idx - 8) + " present");
    }
    if (sizes[1] != body_bytes) {
      return invalid_argument(quoted(path) + ": compressed PCD header disagrees with the data: " +
                              std::to_string(points) + " points x " + std::to_string(header.point_step) +
                              " bytes = " + std::to_string(body_bytes) + ", but " + std::to_string(sizes[1]) +
                              " uncompressed bytes declared");
    }
  }
  return {};
}

// PCL's PLY reader allocates from the header's element counts before it reads a byte of data: a
// count of -5 or 10^12 ends in std::bad_alloc. Every element's count must be a whole number the
// file can hold: at least one byte per item in ascii, the sum of its scalar properties' sizes in
// binary (a list property takes at least its count's size).
constexpr std::uint64_t kMaxPlyHeaderBytes = 64 * 1024;  // real headers are a few hundred bytes

// PCL's reader packs a vertex's colour when it reads `blue`, at the place it saw `red`: colour
// properties in another order, or one missing, made it assert (abort; found by fuzz_ply).
Status check_ply_vertex_colour(const fs::path& path, const std::vector<std::string>& properties) {
  std::vector<std::string> names;
  for (const auto& p : properties) names.push_back(p.rfind("diffuse_", 0) == 0 ? p.substr(8) : p);
  const std::vector<std::string> rgba = {"red", "green", "blue", "alpha"};
  const auto first = std::find_first_of(names.begin(), names.end(), rgba.begin(), rgba.end());
  if (first == names.end()) return {};
  const auto colours = static_cast<std::size_t>(
      std::count_if(names.begin(), names.end(), [&](const std::string& n) { return std::count(rgba.begin(), rgba.end(), n) > 0; }));
  const auto at = static_cast<std::size_t>(first - names.begin());
  bool ok = (colours == 3 || colours == 4) && at + colours <= names.size();
  for (std::size_t k = 0; ok && k < colours; ++k) ok = names[at + k] == rgba[k];
  if (!ok) {
    return invalid_argument(quoted(path) + ": PLY vertex colour must be the properties red, green, blue (then alpha), "
                            "one after the other");
  }
  return {};
}

Status check_ply_header(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line, format;
  std::uint64_t header_bytes = 0, min_body = 0, item_bytes = 0, items = 0, all_items = 0;
  auto flush = [&] {
    min_body += items * std::max<std::uint64_t>(1, item_bytes);
    all_items += items;
  };
  auto scalar_size = [](const std::string& t) -> std::uint64_t {
    if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
    if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
    if (t == "int" || t == "uint" || t == "float" || t == "int32" || t == "uint32" || t == "float32") return 4;
    if (t == "double" || t == "float64") return 8;
    return 0;
  };
  bool ended = false;
  std::string element;
  std::vector<std::string> vertex_properties;
  while (std::getline(in, line)) {
    header_bytes += line.size() + 1;
    if (header_bytes > kMaxPlyHeaderBytes) break;
    std::istringstream words(line);
    std::string word;
    words >> word;
    if (word == "format") words >> format;
    if (word == "element") {
      flush();
      std::string count;
      words >> element >> count;
      const std::string& name = element;
      if (count.empty() || count.find_first_not_of("0123456789") != std::string::npos || count.size() > 18) {
        return invalid_argument(quoted(path) + ": PLY element '" + name + "' has a count that is not a whole number: '" +
                                count + "'");
      }
      items = std::stoull(count);
      item_bytes = 0;
      if (items > fs::file_size(path)) {
        return invalid_argument(quoted(path) + ": PLY element '" + name + "' declares " + count +
                                " items, more than the file's " + std::to_string(fs::file_size(path)) + " bytes");
      }
    }
    if (word == "property") {
      std::string type;
      words >> type;
      // PCL's reader takes a vertex list's length from its first vertex and asserts (aborts) when
      // a later one differs; clouds and meshes have none.
      if (type == "list" && element == "vertex") {
        std::string count_type, item_type, name;
        words >> count_type >> item_type >> name;
        return invalid_argument(quoted(path) + ": PLY vertex property '" + name +
                                "' is a list; vertices must have scalar properties only");
      }
      if (type == "list") words >> type;  // the count's type: a list holds at least its count
      item_bytes += scalar_size(type);
      std::string name;
      if (element == "vertex" && words >> name) vertex_properties.push_back(name);
    }
    if (word == "end_header") {
      ended = true;
      break;
    }
  }
  if (!ended) return invalid_argument(quoted(path) + ": PLY header has no end_header within its first " +
                                      std::to_string(kMaxPlyHeaderBytes) + " bytes");
  if (auto st = check_ply_vertex_colour(path, vertex_properties); !st) return st;
  flush();
  const std::uint64_t body = fs::file_size(path) - std::min<std::uint64_t>(fs::file_size(path), header_bytes);
  // In ascii every item takes at least one character; binary items take their full size.
  const bool ascii = format == "ascii";
  if ((ascii ? all_items : min_body) > body) {
    return invalid_argument(quoted(path) + ": PLY header declares more data than the file holds (" +
                            std::to_string(body) + " bytes after the header)");
  }
  return {};
}

Result<pcl::PCLPointCloud2> read_blob_unguarded(const fs::path& path, Eigen::Vector4f& origin,
                                                Eigen::Quaternionf& orientation) {
  quiet_pcl();
  if (auto st = check_readable_file(path); !st) return st.error();
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  pcl::PCLPointCloud2 blob;
  if (ext == ".pcd") {
    pcl::PCDReader reader;
    pcl::PCLPointCloud2 header;
    int version = 0, data_type = 0;
    unsigned int data_idx = 0;
    if (fs::file_size(path) == 0) return invalid_argument(quoted(path) + ": empty file");
    auto strict = read_pcd_header(path);
    if (!strict) return strict.error();
    if (reader.readHeader(path.string(), header, origin, orientation, version, data_type, data_idx) < 0) {
      return invalid_argument(quoted(path) + ": not a valid PCD header (fields, sizes, width x height = points?)");
    }
    // PCL's readHeader accepts some garbage as an empty header, and read() then crashes on it.
    if (header.fields.empty() || header.point_step == 0) {
      return invalid_argument(quoted(path) + ": not a PCD file (no FIELDS/SIZE in the header)");
    }
    // PCL's header parser accepts malformed lines (a SIZE of '.', a second FIELDS line after DATA)
    // and then reads past its buffers (found by fuzz_pcd): what it made of the header must be
    // what a strict reading says.
    if (header.fields.size() != strict->fields.size() || header.point_step != strict->point_step ||
        static_cast<std::uint64_t>(header.width) * header.height != strict->points || data_type != strict->data_type ||
        data_idx != strict->data_offset) {
      return invalid_argument(quoted(path) + ": malformed PCD header (it can be read in more than one way)");
    }
    if (static_cast<std::uint64_t>(header.width) * header.height == 0) {
      return invalid_argument(quoted(path) + ": header declares no points (WIDTH x HEIGHT = 0)");
    }
    if (data_type < 0 || data_type > 2) return invalid_argument(quoted(path) + ": unknown DATA type in the header");
    if (auto st = check_pcd_body(path, header, data_type, data_idx); !st) return st.error();
    if (reader.read(path.string(), blob, origin, orientation, version) < 0) {
      return invalid_argument(quoted(path) + ": PCD data could not be parsed (truncated or corrupt)");
    }
  } else if (ext == ".ply") {
    if (auto st = check_ply_header(path); !st) return st.error();
    pcl::PLYReader reader;
    int version = 0;
    if (reader.read(path.string(), blob, origin, orientation, version) < 0) {
      return invalid_argument(quoted(path) + ": PLY file could not be parsed (malformed header or truncated data)");
    }
  } else {
    return invalid_argument(quoted(path) + ": unknown extension '" + ext + "' (expected .pcd or .ply)");
  }
  const std::uint64_t points = static_cast<std::uint64_t>(blob.width) * blob.height;
  if (points == 0) return invalid_argument(quoted(path) + ": the file holds no points");
  if (blob.data.size() < points * blob.point_step) {
    return invalid_argument(quoted(path) + ": data shorter than the header declares (" +
                            std::to_string(blob.data.size()) + " bytes for " + std::to_string(points) + " points)");
  }
  return blob;
}

/// PCL's readers throw on some malformed headers (std::out_of_range for a PCD `DATA` line without
/// its type): a bad file is an error naming it, never an abort of the CLI or INTERNAL from the daemon.
template <typename Read>
auto guard_pcl(const fs::path& path, Read&& read) -> decltype(read()) {
  try {
    return read();
  } catch (const std::exception& e) {
    return invalid_argument(quoted(path) + ": not a readable " + path.extension().string() + " file (" + e.what() + ")");
  }
}

Result<pcl::PCLPointCloud2> read_blob(const fs::path& path, Eigen::Vector4f& origin, Eigen::Quaternionf& orientation) {
  return guard_pcl(path, [&] { return read_blob_unguarded(path, origin, orientation); });
}

}  // namespace

Result<CloudFile> read_cloud(const fs::path& path) {
  Eigen::Vector4f origin = Eigen::Vector4f::Zero();
  Eigen::Quaternionf orientation = Eigen::Quaternionf::Identity();
  auto blob = read_blob(path, origin, orientation);
  if (!blob) return blob.error();

  for (const char* axis : {"x", "y", "z"}) {
    const auto* field = find_field(*blob, axis);
    if (field == nullptr) return invalid_argument(quoted(path) + ": no '" + axis + "' field");
    if (field->datatype != pcl::PCLPointField::FLOAT32) {
      return invalid_argument(quoted(path) + ": field '" + axis + "' is not float32 (type " +
                              std::to_string(field->datatype) + "); only float32 coordinates are supported");
    }
  }
  const bool has_color = find_field(*blob, "rgb") != nullptr || find_field(*blob, "rgba") != nullptr;

  CloudFile out;
  out.cloud = std::make_shared<Cloud>();
  // PCL's field mapping matches 'rgb' with 'rgba' and ignores fields the point type lacks (label).
  pcl::fromPCLPointCloud2(*blob, *out.cloud);
  Cloud& cloud = *out.cloud;
  std::size_t valid = 0;
  for (auto& p : cloud.points) {
    if (!has_color) p.r = p.g = p.b = 128;
    if (is_valid(p)) {
      ++valid;
    } else {
      // Inf counts as invalid as NaN does; downstream code tests std::isfinite only.
      p.x = p.y = p.z = std::numeric_limits<float>::quiet_NaN();
    }
  }
  if (valid == 0) return invalid_argument(quoted(path) + ": no valid points (all " + std::to_string(cloud.size()) +
                                          " points are NaN or non-finite)");
  cloud.is_dense = valid == cloud.size();
  out.has_color = has_color;
  out.organized = cloud.height > 1;
  out.valid_points = valid;
  out.sensor_origin = origin.head<3>().cast<double>();
  cloud.sensor_origin_ = origin;
  cloud.sensor_orientation_ = orientation;
  return out;
}

Result<std::vector<std::uint32_t>> read_pcd_labels(const fs::path& path) {
  Eigen::Vector4f origin;
  Eigen::Quaternionf orientation;
  auto blob = read_blob(path, origin, orientation);
  if (!blob) return blob.error();
  const auto* field = find_field(*blob, "label");
  if (field == nullptr) return invalid_argument(quoted(path) + ": no 'label' field");
  if (field->datatype != pcl::PCLPointField::UINT32 && field->datatype != pcl::PCLPointField::INT32) {
    return invalid_argument(quoted(path) + ": field 'label' is not a 32-bit integer");
  }
  const std::size_t n = static_cast<std::size_t>(blob->width) * blob->height;
  std::vector<std::uint32_t> labels(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::memcpy(&labels[i], &blob->data[i * blob->point_step + field->offset], sizeof(std::uint32_t));
  }
  return labels;
}

Status write_pcd(const fs::path& path, const Cloud& cloud) {
  quiet_pcl();
  if (cloud.empty()) return invalid_argument(quoted(path) + ": refusing to write an empty cloud");
  return write_atomically(path, [&](const fs::path& tmp) -> Status {
    pcl::PCDWriter writer;
    return with_system_reason([&]() -> Status {
      if (writer.writeBinary(tmp.string(), cloud) < 0) return io_error(quoted(path) + ": cannot write");
      return {};
    });
  });
}

Status write_ply(const fs::path& path, const Cloud& cloud) {
  quiet_pcl();
  if (cloud.empty()) return invalid_argument(quoted(path) + ": refusing to write an empty cloud");
  return write_atomically(path, [&](const fs::path& tmp) -> Status {
    pcl::PLYWriter writer;
    return with_system_reason([&]() -> Status {
      if (writer.write(tmp.string(), cloud, true, false) < 0) return io_error(quoted(path) + ": cannot write");
      return {};
    });
  });
}

Status write_mesh_ply(const fs::path& path, const ColoredMesh& mesh) {
  quiet_pcl();
  if (mesh.empty()) return invalid_argument(quoted(path) + ": refusing to write a mesh without triangles");
  if (mesh.colors.size() != mesh.vertices.size())
    return invalid_argument(quoted(path) + ": mesh has " + std::to_string(mesh.vertices.size()) + " vertices but " +
                            std::to_string(mesh.colors.size()) + " colours");
  Cloud vertices;
  vertices.resize(mesh.vertices.size());
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    PointT& p = vertices[i];
    p.getVector3fMap() = mesh.vertices[i];
    p.r = mesh.colors[i][0];
    p.g = mesh.colors[i][1];
    p.b = mesh.colors[i][2];
  }
  pcl::PolygonMesh out;
  pcl::toPCLPointCloud2(vertices, out.cloud);
  out.polygons.resize(mesh.triangles.size());
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    for (std::uint32_t v : mesh.triangles[i]) out.polygons[i].vertices.push_back(static_cast<pcl::index_t>(v));
  }
  return write_atomically(path, [&](const fs::path& tmp) -> Status {
    return with_system_reason([&]() -> Status {
      if (pcl::io::savePLYFileBinary(tmp.string(), out) < 0) return io_error(quoted(path) + ": cannot write");
      return {};
    });
  });
}

Result<ColoredMesh> read_mesh_ply(const fs::path& path) {
  quiet_pcl();
  if (auto st = check_readable_file(path); !st) return st.error();
  pcl::PolygonMesh in;
  if (auto st = check_ply_header(path); !st) return st.error();
  Cloud vertices;
  const Status loaded = guard_pcl(path, [&]() -> Status {
    if (pcl::io::loadPLYFile(path.string(), in) < 0) return invalid_argument(quoted(path) + ": not a readable PLY mesh");
    pcl::fromPCLPointCloud2(in.cloud, vertices);
    return {};
  });
  if (!loaded) return loaded.error();
  ColoredMesh mesh;
  mesh.vertices.reserve(vertices.size());
  for (const auto& p : vertices.points) {
    mesh.vertices.push_back(p.getVector3fMap());
    mesh.colors.push_back({p.r, p.g, p.b});
  }
  for (const auto& poly : in.polygons) {
    if (poly.vertices.size() != 3) return invalid_argument(quoted(path) + ": a face is not a triangle");
    std::array<std::uint32_t, 3> tri{};
    for (int k = 0; k < 3; ++k) {
      const auto v = poly.vertices[static_cast<std::size_t>(k)];
      if (v < 0 || static_cast<std::size_t>(v) >= mesh.vertices.size())
        return invalid_argument(quoted(path) + ": a face indexes a missing vertex");
      tri[static_cast<std::size_t>(k)] = static_cast<std::uint32_t>(v);
    }
    mesh.triangles.push_back(tri);
  }
  return mesh;
}

}  // namespace scenewatch::io
