#include "frame_spec.h"

#include <filesystem>
#include <iostream>

#include "scenewatch/io/rgbd.h"
#include "scenewatch/io/sequence.h"

namespace scenewatch::cli {
namespace fs = std::filesystem;
namespace {

struct Parsed {
  std::string path;
  std::string frame_name;  // DIR/frame-NNNNNN: the frame of that name
  bool sequence = false;
  bool bag = false;  // a ROS bag (sequence is true too: it names frames)
  std::size_t first = 0, last = 0;  // inclusive; last = SIZE_MAX: to the end
};

Result<std::size_t> parse_index(const std::string& text, const std::string& spec) {
  if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos)
    return invalid_argument("'" + spec + "': '" + text + "' is not a frame number");
  return static_cast<std::size_t>(std::stoull(text));
}

Result<Parsed> parse(const std::string& spec) {
  Parsed p;
  p.path = spec;
  p.last = static_cast<std::size_t>(-1);
  std::error_code ec;
  const fs::path as_path(spec);
  if (!fs::exists(spec, ec) && as_path.has_parent_path() && io::is_sequence_dir(as_path.parent_path())) {
    p.path = as_path.parent_path().string();
    p.frame_name = as_path.filename().string();
    p.sequence = true;
    return p;
  }
  const auto colon = spec.rfind(':');
  const char* not_frames = "is not a sequence folder (frame-NNNNNN.color.png or .color.jpg, or a TUM rgb.txt) nor a ROS bag (.bag, .db3, .mcap, or a rosbag2 folder with metadata.yaml)";
  if (!fs::exists(spec, ec) && colon != std::string::npos) {
    p.path = spec.substr(0, colon);
    const std::string range = spec.substr(colon + 1);
    const auto dash = range.find('-');
    auto first = parse_index(range.substr(0, dash), spec);
    if (!first) return first.error();
    p.first = p.last = *first;
    if (dash != std::string::npos) {
      auto last = parse_index(range.substr(dash + 1), spec);
      if (!last) return last.error();
      if (*last < *first) return invalid_argument("'" + spec + "': the range ends before it starts");
      p.last = *last;
    }
    if (!io::is_sequence_dir(p.path) && !io::is_bag(p.path)) return invalid_argument("'" + p.path + "' " + not_frames);
  }
  if (!fs::exists(p.path, ec)) return not_found("'" + p.path + "': no such file or folder");
  p.bag = io::is_bag(p.path) && !io::is_sequence_dir(p.path);
  p.sequence = p.bag || fs::is_directory(p.path, ec);
  if (p.sequence && !p.bag && !io::is_sequence_dir(p.path)) return invalid_argument("'" + p.path + "' " + not_frames);
  return p;
}

// DIR/frame-NNNNNN: the index of the frame of that name.
Status resolve_name(Parsed& p, const io::Sequence& seq, const std::string& spec) {
  if (p.frame_name.empty()) return {};
  for (std::size_t i = 0; i < seq.frames.size(); ++i) {
    if (seq.frames[i].name == p.frame_name) {
      p.first = p.last = i;
      return {};
    }
  }
  return not_found("'" + spec + "': no frame named '" + p.frame_name + "' in the sequence '" + p.path + "'");
}

}  // namespace

io::SequenceOptions sequence_options(const std::optional<double>& depth_scale_m) {
  io::SequenceOptions options;
  options.depth_scale_m = depth_scale_m;
  return options;
}

std::string SequenceSpan::frame_name(std::size_t index) const {
  if (bag) return folder + ":" + std::to_string(index);
  return (fs::path(folder) / sequence.frames[index].name).string();
}

Result<Frame> SequenceSpan::load(std::size_t index) const {
  if (bag) return io::load_bag_frame(*bag, index);
  return io::load_sequence_frame(sequence, index);
}

std::string SequenceSpan::skipped(const InputOptions& inputs) const {
  if (bag) return io::skipped_summary(*bag, inputs.bag);
  return io::skipped_summary(sequence, inputs.sequence);
}

Result<std::size_t> count_frames(const std::string& spec, const InputOptions& inputs) {
  auto span = sequence_span(spec, inputs);
  if (!span) return span.error();
  return *span ? (*span)->last - (*span)->first + 1 : std::size_t{1};
}

Result<std::optional<SequenceSpan>> sequence_span(const std::string& spec, const InputOptions& inputs) {
  auto p = parse(spec);
  if (!p) return p.error();
  if (!p->sequence) return std::optional<SequenceSpan>();
  SequenceSpan span;
  span.folder = p->path;
  std::size_t n = 0;
  if (p->bag) {
    auto recording = io::open_bag(p->path, inputs.bag);
    if (!recording) return recording.error();
    span.bag = std::make_shared<io::Recording>(std::move(*recording));
    n = span.bag->frames.size();
    if (p->first >= n) return invalid_argument("'" + spec + "': the bag has " + std::to_string(n) + " frames");
  } else {
    auto seq = io::open_sequence(p->path, inputs.sequence);
    if (!seq) return seq.error();
    if (auto st = resolve_name(*p, *seq, spec); !st) return st.error();
    n = seq->frames.size();
    if (p->first >= n) return invalid_argument("'" + spec + "': the sequence has " + std::to_string(n) + " frames");
    span.sequence = std::move(*seq);
  }
  span.first = p->first;
  span.last = std::min(p->last, n - 1);
  return std::optional<SequenceSpan>(std::move(span));
}

Status for_each_frame(const std::string& spec, const std::optional<Intrinsics>& intrinsics,
                      const std::function<Status(Frame)>& each, const InputOptions& inputs) {
  auto span = sequence_span(spec, inputs);
  if (!span) return span.error();
  if (!*span) {
    auto frame = io::load_cloud_frame(spec);
    if (!frame) return frame.error();
    if (intrinsics) {
      frame->intrinsics = *intrinsics;
      frame->intrinsics->width = static_cast<int>(frame->cloud->width);
      frame->intrinsics->height = static_cast<int>(frame->cloud->height);
    } else if (!frame->intrinsics && frame->cloud->height > 1) {
      // Left unset when the cloud is not a pinhole image (commands that need intrinsics say so).
      if (auto K = io::estimate_intrinsics(*frame->cloud)) frame->intrinsics = *K;
    }
    return each(std::move(*frame));
  }
  const SequenceSpan& s = **span;
  if (auto skipped = s.skipped(inputs); !skipped.empty()) {
    std::cerr << "scenewatch: " << s.folder << ": " << skipped << "\n";
  }
  for (std::size_t i = s.first; i <= s.last; ++i) {
    auto frame = s.load(i);
    if (!frame) return frame.error();
    if (auto st = each(std::move(*frame)); !st) return st;
  }
  return {};
}

Result<Frame> load_one_frame(const std::string& spec, const InputOptions& inputs) {
  auto n = count_frames(spec, inputs);
  if (!n) return n.error();
  if (*n != 1) {
    return invalid_argument("'" + spec + "' names " + std::to_string(*n) + " frames: name one, e.g. '" + spec +
                            ":0'" + (io::is_bag(spec) ? std::string() : " or '" + (fs::path(spec) / "frame-000000").string() + "'"));
  }
  std::optional<Frame> frame;
  auto st = for_each_frame(
      spec, std::nullopt,
      [&](Frame f) -> Status {
        frame = std::move(f);
        return {};
      },
      inputs);
  if (!st) return st.error();
  return std::move(*frame);
}

}  // namespace scenewatch::cli
