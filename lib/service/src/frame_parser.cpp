#include "scenewatch/service/frame_parser.h"

#include <algorithm>
#include <cassert>
#include <iterator>
#include <utility>

namespace scenewatch::service {
namespace {
constexpr std::size_t kInitialReserveBytes = 64 * 1024;
}  // namespace

void put_frame_header(std::uint32_t payload_bytes, char* out) {
  out[0] = static_cast<char>((payload_bytes >> 24) & 0xFF);
  out[1] = static_cast<char>((payload_bytes >> 16) & 0xFF);
  out[2] = static_cast<char>((payload_bytes >> 8) & 0xFF);
  out[3] = static_cast<char>(payload_bytes & 0xFF);
}

std::string encode_frame(std::string_view payload) {
  assert(!payload.empty() && payload.size() <= kMaxEncodableFrameBytes);
  std::string out;
  out.reserve(kFrameHeaderBytes + payload.size());
  out.resize(kFrameHeaderBytes);
  put_frame_header(static_cast<std::uint32_t>(payload.size()), out.data());
  out.append(payload);
  return out;
}

FrameParser::FrameParser(std::size_t max_payload_bytes, std::shared_ptr<FrameBudget> budget)
    : max_payload_bytes_(std::max<std::size_t>(1, max_payload_bytes)), budget_(std::move(budget)) {}

FrameParser::~FrameParser() { release_payload(); }

FrameParser::FrameParser(FrameParser&& other) noexcept
    : max_payload_bytes_(other.max_payload_bytes_),
      budget_(std::move(other.budget_)),
      header_fill_(other.header_fill_),
      expected_(other.expected_),
      payload_(std::move(other.payload_)),
      ready_(std::move(other.ready_)),
      failed_(other.failed_) {
  std::copy(std::begin(other.header_), std::end(other.header_), std::begin(header_));
}

FrameParser& FrameParser::operator=(FrameParser&& other) noexcept {
  if (this == &other) return *this;
  release_payload();
  max_payload_bytes_ = other.max_payload_bytes_;
  budget_ = std::move(other.budget_);
  std::copy(std::begin(other.header_), std::end(other.header_), std::begin(header_));
  header_fill_ = other.header_fill_;
  expected_ = other.expected_;
  payload_ = std::move(other.payload_);
  ready_ = std::move(other.ready_);
  failed_ = other.failed_;
  return *this;
}

void FrameParser::release_payload() {
  if (budget_) budget_->release(payload_.capacity());
  payload_.clear();
}

std::size_t FrameParser::drop_partial() {
  const std::size_t freed = payload_.capacity();
  release_payload();
  header_fill_ = 0;
  expected_ = 0;
  failed_ = true;
  return freed;
}

// The buffer grows to the larger of what is needed and twice what it holds (at least 64 KiB, at
// most the declared length, in whole pages), so memory follows the bytes actually received. Each
// step is booked before it is mapped; growing moves pages, it copies nothing, so only the growth
// is booked.
Status FrameParser::reserve_payload(std::size_t needed) {
  if (needed <= payload_.capacity()) return {};
  const std::size_t held = payload_.capacity();
  const std::size_t target =
      FrameBuffer::capacity_for(std::min(expected_, std::max({needed, 2 * held, kInitialReserveBytes})));
  const auto refuse = [&](const std::string& why) -> Status {
    failed_ = true;
    const std::size_t received = buffered_bytes();
    release_payload();
    return Error{ErrorCode::kUnavailable, why + " (this one " + std::to_string(received) + " of " +
                                              std::to_string(expected_) + " bytes)"};
  };
  if (budget_ && !budget_->try_reserve(target - held)) {
    return refuse("unfinished frames of all clients would hold more than " + std::to_string(budget_->limit()) +
                  " bytes");
  }
  if (!payload_.reserve(target)) {
    if (budget_) budget_->release(target - held);
    return refuse("the system refused " + std::to_string(target) + " bytes for an unfinished frame");
  }
  return {};
}

Status FrameParser::feed(std::string_view bytes) {
  if (failed_) return invalid_argument("framing already broken; no further data is accepted");
  while (!bytes.empty()) {
    if (header_fill_ < kFrameHeaderBytes) {
      while (header_fill_ < kFrameHeaderBytes && !bytes.empty()) {
        header_[header_fill_++] = static_cast<unsigned char>(bytes.front());
        bytes.remove_prefix(1);
      }
      if (header_fill_ < kFrameHeaderBytes) break;
      const std::uint64_t declared = (std::uint64_t{header_[0]} << 24) | (std::uint64_t{header_[1]} << 16) |
                                     (std::uint64_t{header_[2]} << 8) | std::uint64_t{header_[3]};
      // Checked before anything is reserved for the payload: a hostile length costs nothing.
      if (declared == 0) {
        failed_ = true;
        return invalid_argument("frame declares a length of 0 bytes; a message must not be empty");
      }
      if (declared > max_payload_bytes_) {
        failed_ = true;
        return invalid_argument("frame declares a length of " + std::to_string(declared) +
                                " bytes, above the maximum of " + std::to_string(max_payload_bytes_) +
                                " bytes");
      }
      expected_ = static_cast<std::size_t>(declared);
    }
    const std::size_t take = std::min(expected_ - payload_.size(), bytes.size());
    if (Status s = reserve_payload(payload_.size() + take); !s) return s;
    payload_.append(bytes.data(), take);
    bytes.remove_prefix(take);
    if (payload_.size() == expected_) {
      const std::size_t booked = payload_.capacity();
      ready_.push_back(payload_.take());
      if (budget_) budget_->release(booked);
      header_fill_ = 0;
      expected_ = 0;
    }
  }
  return {};
}

std::optional<std::string> FrameParser::next() {
  if (ready_.empty()) return std::nullopt;
  std::string out = std::move(ready_.front());
  ready_.pop_front();
  return out;
}

bool FrameParser::has_partial() const { return !failed_ && header_fill_ > 0; }

}  // namespace scenewatch::service
