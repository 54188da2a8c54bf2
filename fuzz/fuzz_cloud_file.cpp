// The cloud readers: arbitrary bytes as a .pcd (fuzz_pcd) or .ply (fuzz_ply) file, as IngestFile,
// `scenewatch segment` and `diff` meet them. io::read_cloud, load_cloud_frame, and the format's
// other reader: the label reader of mOSD ground truth (PCD), the mesh reader of the appearance
// memory (PLY). SCENEWATCH_FUZZ_PLY picks the format.
#include <cstdint>
#include <cstdlib>

#include "fuzz_files.h"
#include "scenewatch/io/cloud_io.h"
#include "scenewatch/io/sequence.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace scenewatch;
#ifdef SCENEWATCH_FUZZ_PLY
  const auto path = fuzz::write_scratch("input.ply", data, size);
#else
  const auto path = fuzz::write_scratch("input.pcd", data, size);
#endif
  if (auto cloud = io::read_cloud(path); cloud.ok()) {
    // What it accepts is consistent: as many points as width x height, some of them valid.
    const auto& c = *cloud->cloud;
    if (c.points.size() != static_cast<std::size_t>(c.width) * c.height) std::abort();
    if (cloud->valid_points == 0 || cloud->valid_points > c.points.size()) std::abort();
  } else if (cloud.error().message.empty()) {
    std::abort();
  }
  (void)io::load_cloud_frame(path);
#ifdef SCENEWATCH_FUZZ_PLY
  (void)io::read_mesh_ply(path);
#else
  (void)io::read_pcd_labels(path);
#endif
  return 0;
}
