// The image verifier on its own: the SHA-256 it computes a slice at a time
// against published and precomputed digests, the units each slice costs
// (kUpdateHashUnitsPer64Bytes a started 64-byte piece, at most
// kUpdateHashBytesPerCycle a step), and the checks an image must pass before
// it may run on a robot of the running geometry.

#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include <cdcr/firmware/update/image_verifier.hpp>

#include "../support/synthetic_image.hpp"

namespace cdcr::firmware {
namespace {

using protocol::UpdateReason;

constexpr std::uint32_t kPiece = kUpdateHashUnitsPer64Bytes;

// Digests from Python's hashlib.
constexpr std::uint8_t kAbcDigest[kSha256Bytes] = {
    0xba, 0x78, 0x16, 0xbf, 0x8f, 0x01, 0xcf, 0xea, 0x41, 0x41, 0x40, 0xde, 0x5d, 0xae, 0x22, 0x23,
    0xb0, 0x03, 0x61, 0xa3, 0x96, 0x17, 0x7a, 0x9c, 0xb4, 0x10, 0xff, 0x61, 0xf2, 0x00, 0x15, 0xad};
// bytes (7 i + 3) mod 256, i < 1000
constexpr std::uint8_t kPatternDigest[kSha256Bytes] = {
    0x1e, 0x9b, 0xc3, 0x8c, 0xbf, 0x86, 0x0b, 0x9e, 0xc3, 0x19, 0x18, 0xb0, 0x65, 0xf9, 0xb5, 0x24,
    0x76, 0xc5, 0x49, 0xa7, 0x82, 0xe0, 0xe7, 0x99, 0x0b, 0xed, 0x8c, 0xe3, 0x86, 0x8d, 0x23, 0x71};

std::vector<std::uint8_t> pattern() {
  std::vector<std::uint8_t> bytes(1000);
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<std::uint8_t>((7 * i + 3) % 256);
  return bytes;
}

TEST(ImageVerifierTest, HashesAShortInputInOneStep) {
  const std::uint8_t abc[] = {'a', 'b', 'c'};
  ImageVerifier verifier;
  verifier.begin(abc, 3);
  EXPECT_FALSE(verifier.hashed());
  EXPECT_EQ(verifier.step(kPiece), kPiece);
  EXPECT_TRUE(verifier.hashed());
  EXPECT_TRUE(verifier.digest_matches(kAbcDigest));
}

TEST(ImageVerifierTest, HashesInSlicesAndChargesEveryStartedPiece) {
  const std::vector<std::uint8_t> bytes = pattern();
  ImageVerifier verifier;
  verifier.begin(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
  // Too few units for a piece: nothing hashed, nothing spent.
  EXPECT_EQ(verifier.step(kPiece - 1), 0u);
  // 3 pieces and a remainder of units that buys none: 192 bytes.
  EXPECT_EQ(verifier.step(3 * kPiece + kPiece - 1), 3 * kPiece);
  // Units for 100 pieces buy kUpdateHashBytesPerCycle (1024 bytes, 16
  // pieces), of which 808 remain: 13 pieces, the last one started.
  EXPECT_EQ(verifier.step(100 * kPiece), 13 * kPiece);
  EXPECT_TRUE(verifier.hashed());
  EXPECT_EQ(verifier.step(100 * kPiece), 0u);
  EXPECT_TRUE(verifier.digest_matches(kPatternDigest));
}

TEST(ImageVerifierTest, AStepHashesAtMostItsCycleShare) {
  const std::vector<std::uint8_t> bytes(1500, 0x5A);
  ImageVerifier verifier;
  verifier.begin(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
  EXPECT_EQ(verifier.step(1000 * kPiece), kUpdateHashBytesPerCycle / 64 * kPiece);
  EXPECT_FALSE(verifier.hashed());
  // The remaining 476 bytes: 8 pieces, the last one started.
  EXPECT_EQ(verifier.step(1000 * kPiece), 8 * kPiece);
  EXPECT_TRUE(verifier.hashed());
}

TEST(ImageVerifierTest, AnotherDigestDoesNotMatch) {
  const std::vector<std::uint8_t> bytes = pattern();
  ImageVerifier verifier;
  verifier.begin(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
  while (!verifier.hashed()) verifier.step(kUpdateHashBytesPerCycle / 64 * kPiece);
  std::uint8_t wrong[kSha256Bytes];
  std::copy(std::begin(kPatternDigest), std::end(kPatternDigest), wrong);
  wrong[kSha256Bytes - 1] ^= 0x01;
  EXPECT_FALSE(verifier.digest_matches(wrong));
}

class ImageCheckTest : public ::testing::Test {
 protected:
  // Hashes and scans `bytes` whole, then checks it against `running`.
  UpdateReason check(const std::vector<std::uint8_t>& bytes, const ImageVerifier::Geometry& running) {
    verifier.begin(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
    while (!verifier.hashed()) verifier.step(kUpdateHashBytesPerCycle / 64 * kPiece);
    return verifier.check(running);
  }

  // The robot the synthetic model was made for (synthetic_trained_model.hpp).
  static ImageVerifier::Geometry robot() {
    ImageVerifier::Geometry g = ImageVerifier::Geometry::uniform(2, 120.0f, 67.0f);
    g.segments[1].backbone_length_mm = 95.5f;
    return g;
  }

  test_support::SyntheticImage image = test_support::synthetic_image({});
  ImageVerifier verifier;
};

TEST_F(ImageCheckTest, AnIntactImageForThisRobotPasses) {
  EXPECT_EQ(check(image.bytes, robot()), UpdateReason::none);
}

TEST_F(ImageCheckTest, GeometryWithinFivePercentPassesBeyondItIsRefused) {
  ImageVerifier::Geometry g = robot();
  g.segments[0].backbone_length_mm = 120.0f * 1.04f;
  EXPECT_EQ(check(image.bytes, g), UpdateReason::none);
  g.segments[0].backbone_length_mm = 120.0f * 1.06f;
  EXPECT_EQ(check(image.bytes, g), UpdateReason::wrong_geometry);
  g = robot();
  g.segments[1].anchor_radius_mm = 67.0f * 0.94f;
  EXPECT_EQ(check(image.bytes, g), UpdateReason::wrong_geometry);
}

TEST_F(ImageCheckTest, AnotherSegmentCountIsRefused) {
  EXPECT_EQ(check(image.bytes, ImageVerifier::Geometry::uniform(3, 120.0f, 67.0f)), UpdateReason::wrong_segment_count);
}

TEST_F(ImageCheckTest, AFlippedBitIsAnInvalidImage) {
  std::vector<std::uint8_t> corrupted = image.bytes;
  corrupted[corrupted.size() / 2] ^= 0x10;
  EXPECT_EQ(check(corrupted, robot()), UpdateReason::image_invalid);
}

}  // namespace
}  // namespace cdcr::firmware
