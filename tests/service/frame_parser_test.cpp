#include "scenewatch/service/frame_parser.h"

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

namespace scenewatch::service {
namespace {

std::vector<std::string> sample_payloads() {
  std::string binary(300, '\0');
  for (std::size_t i = 0; i < binary.size(); ++i) binary[i] = static_cast<char>(i * 7);
  return {"a", "hello, world", binary, std::string(1, '\0'), "last"};
}

std::string concatenated(const std::vector<std::string>& payloads) {
  std::string stream;
  for (const auto& p : payloads) stream += encode_frame(p);
  return stream;
}

std::vector<std::string> drain(FrameParser& parser) {
  std::vector<std::string> out;
  while (auto frame = parser.next()) out.push_back(std::move(*frame));
  return out;
}

TEST(FrameParserTest, EncodeWritesBigEndianLength) {
  const std::string frame = encode_frame(std::string(0x010203, 'x'));
  ASSERT_EQ(frame.size(), 4u + 0x010203);
  EXPECT_EQ(static_cast<unsigned char>(frame[0]), 0x00);
  EXPECT_EQ(static_cast<unsigned char>(frame[1]), 0x01);
  EXPECT_EQ(static_cast<unsigned char>(frame[2]), 0x02);
  EXPECT_EQ(static_cast<unsigned char>(frame[3]), 0x03);
}

TEST(FrameParserTest, WholeStreamAtOnce) {
  const auto payloads = sample_payloads();
  FrameParser parser(1024);
  ASSERT_TRUE(parser.feed(concatenated(payloads)).ok());
  EXPECT_EQ(drain(parser), payloads);
  EXPECT_FALSE(parser.has_partial());
}

TEST(FrameParserTest, SplitAtEveryByteBoundary) {
  const auto payloads = sample_payloads();
  const std::string stream = concatenated(payloads);
  for (std::size_t split = 0; split <= stream.size(); ++split) {
    FrameParser parser(1024);
    ASSERT_TRUE(parser.feed(std::string_view(stream).substr(0, split)).ok()) << "split " << split;
    std::vector<std::string> got = drain(parser);
    ASSERT_TRUE(parser.feed(std::string_view(stream).substr(split)).ok()) << "split " << split;
    for (auto& f : drain(parser)) got.push_back(std::move(f));
    EXPECT_EQ(got, payloads) << "split " << split;
    EXPECT_FALSE(parser.has_partial()) << "split " << split;
  }
}

TEST(FrameParserTest, OneByteAtATime) {
  const auto payloads = sample_payloads();
  const std::string stream = concatenated(payloads);
  FrameParser parser(1024);
  std::vector<std::string> got;
  std::size_t complete_bytes = 0;
  for (std::size_t i = 0; i < stream.size(); ++i) {
    ASSERT_TRUE(parser.feed(std::string_view(&stream[i], 1)).ok());
    for (auto& f : drain(parser)) {
      complete_bytes += 4 + f.size();
      got.push_back(std::move(f));
    }
    // Partial exactly when bytes of an unfinished frame are held.
    EXPECT_EQ(parser.has_partial(), complete_bytes != i + 1) << "byte " << i;
  }
  EXPECT_EQ(got, payloads);
}

TEST(FrameParserTest, PayloadOfExactlyTheMaximumIsAccepted) {
  FrameParser parser(16);
  ASSERT_TRUE(parser.feed(encode_frame(std::string(16, 'm'))).ok());
  auto frame = parser.next();
  ASSERT_TRUE(frame.has_value());
  EXPECT_EQ(*frame, std::string(16, 'm'));
}

TEST(FrameParserTest, OversizedLengthIsRejectedFromTheHeaderAlone) {
  FrameParser parser(1000);
  // Header only: 1001 bytes declared. The error comes before any payload byte arrives.
  const std::string header("\x00\x00\x03\xE9", 4);
  const Status status = parser.feed(header);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().message.find("1001"), std::string::npos) << status.error().message;
  EXPECT_NE(status.error().message.find("1000"), std::string::npos) << status.error().message;
  EXPECT_TRUE(parser.failed());
  EXPECT_LE(parser.buffered_bytes(), kFrameHeaderBytes);  // nothing reserved for the payload
  EXPECT_FALSE(parser.next().has_value());
  // The stream cannot be resynchronised: further bytes are refused.
  EXPECT_FALSE(parser.feed(encode_frame("x")).ok());
}

TEST(FrameParserTest, HugeDeclaredLengthIsRejected) {
  FrameParser parser(64u << 20);
  const Status status = parser.feed(std::string("\xFF\xFF\xFF\xFF", 4) + "abc");
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().message.find("4294967295"), std::string::npos) << status.error().message;
  EXPECT_NE(status.error().message.find(std::to_string(64u << 20)), std::string::npos) << status.error().message;
}

TEST(FrameParserTest, OversizedLengthSplitAcrossChunksIsRejected) {
  FrameParser parser(255);
  ASSERT_TRUE(parser.feed(std::string("\x00\x00", 2)).ok());
  ASSERT_TRUE(parser.feed(std::string("\x01", 1)).ok());
  EXPECT_TRUE(parser.has_partial());
  const Status status = parser.feed(std::string("\x00", 1));  // 256
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().message.find("256"), std::string::npos);
  EXPECT_NE(status.error().message.find("255"), std::string::npos);
}

TEST(FrameParserTest, ZeroLengthIsRejected) {
  FrameParser parser(1024);
  const Status status = parser.feed(std::string(4, '\0'));
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().message.find("length of 0"), std::string::npos) << status.error().message;
  EXPECT_TRUE(parser.failed());
}

TEST(FrameParserTest, FramesBeforeABrokenHeaderAreStillDelivered) {
  FrameParser parser(1024);
  const Status status = parser.feed(encode_frame("good") + std::string(4, '\0'));
  EXPECT_FALSE(status.ok());
  auto frame = parser.next();
  ASSERT_TRUE(frame.has_value());
  EXPECT_EQ(*frame, "good");
}

// The budget counts what is reserved, step by step, before it is reserved: a frame announced and
// dripped holds its first 64 KiB step, a growing frame doubles its step (the growth is booked: the
// pages move, nothing is copied). Completed and dropped frames give their share back.
TEST(FrameParserTest, TheBudgetCountsEachBufferStepBeforeItIsReserved) {
  auto budget = std::make_shared<FrameBudget>(300 * 1024);
  FrameParser parser(1u << 20, budget);
  const std::string header("\x00\x10\x00\x00", 4);  // 1 MiB announced
  ASSERT_TRUE(parser.feed(header + "x").ok());
  EXPECT_EQ(budget->reserved(), 64u * 1024) << "the first step";
  EXPECT_EQ(parser.reserved_bytes(), 64u * 1024);
  ASSERT_TRUE(parser.feed(std::string(64 * 1024, 'x')).ok());  // 64 KiB + 1 received
  EXPECT_EQ(budget->reserved(), 128u * 1024) << "doubled";

  // A second parser on the same budget takes 100 KiB at once (a step is at least what the bytes
  // need); then the first cannot grow: its next step, to 256 KiB, needs 128 KiB more beside its
  // 128 KiB and the other's 100 KiB.
  FrameParser other(1u << 20, budget);
  ASSERT_TRUE(other.feed(header + std::string(100 * 1024, 'y')).ok());
  EXPECT_EQ(budget->reserved(), 128u * 1024 + 100u * 1024);
  const Status refused = parser.feed(std::string(64 * 1024, 'x'));
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error().code, ErrorCode::kUnavailable);
  EXPECT_NE(refused.error().message.find("307200 bytes"), std::string::npos) << refused.error().message;
  EXPECT_TRUE(parser.failed());
  EXPECT_EQ(budget->reserved(), 100u * 1024) << "the refused frame's share is given back";
  EXPECT_EQ(other.drop_partial(), 100u * 1024);
  EXPECT_EQ(budget->reserved(), 0u);
}

TEST(FrameParserTest, ACompleteFrameLeavesTheBudgetAndAMovedParserKeepsItsShare) {
  auto budget = std::make_shared<FrameBudget>(1u << 20);
  FrameParser parser(1u << 20, budget);
  const std::string payload(200 * 1024, 'p');
  const std::string frame = encode_frame(payload);
  ASSERT_TRUE(parser.feed(std::string_view(frame).substr(0, 1000)).ok());
  EXPECT_GT(budget->reserved(), 0u);
  FrameParser moved = std::move(parser);
  EXPECT_EQ(budget->reserved(), moved.reserved_bytes());
  ASSERT_TRUE(moved.feed(std::string_view(frame).substr(1000)).ok());
  EXPECT_EQ(budget->reserved(), 0u) << "a complete frame is no longer an unfinished one";
  auto out = moved.next();
  ASSERT_TRUE(out.has_value());
  EXPECT_EQ(*out, payload);
  {
    FrameParser gone(1u << 20, budget);
    ASSERT_TRUE(gone.feed(std::string_view(frame).substr(0, 5000)).ok());
    EXPECT_GT(budget->reserved(), 0u);
  }
  EXPECT_EQ(budget->reserved(), 0u) << "a parser that goes gives its share back";
}

}  // namespace
}  // namespace scenewatch::service
