#include "codebook.h"

#include <gtest/gtest.h>

#include <fstream>
#include <random>

#include "tessera/errors.h"
#include "test_support.h"

namespace tessera::retrieval {
namespace {

Codebook SmallCodebook() {
  Codebook codebook;
  codebook.descriptor_dimension = 3;
  codebook.num_centers = 2;
  codebook.centers = {0.5f, -1.25f, 3e-8f, 7.f, 0.f, -0.f};
  return codebook;
}

std::string ParseError(const std::string& bytes) {
  try {
    ParseCodebook(bytes, "cb.bin");
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(RetrievalCodebook, FileRoundTripIsByteExact) {
  testing::TemporaryDir dir;
  const Codebook codebook = SmallCodebook();
  WriteCodebook(codebook, dir.path() / "cb.bin");
  const std::string bytes = SerializeCodebook(codebook);
  EXPECT_EQ(bytes.size(), kCodebookHeaderBytes + 4 * 6 + 8);
  EXPECT_EQ(bytes.substr(0, 8), std::string("TSRVLAD\0", 8));
  const Codebook read = ReadCodebook(dir.path() / "cb.bin");
  EXPECT_EQ(read.descriptor_dimension, 3);
  EXPECT_EQ(read.num_centers, 2);
  EXPECT_EQ(read.metric, DescriptorMetric::kL2);
  EXPECT_EQ(read.centers, codebook.centers);
  EXPECT_EQ(SerializeCodebook(read), bytes);
}

TEST(RetrievalCodebook, RefusesBadFilesWithTheirName) {
  const std::string good = SerializeCodebook(SmallCodebook());
  EXPECT_EQ(ParseError(good), "");
  EXPECT_EQ(ParseError(""),
            "cb.bin: not a valid retrieval codebook: file is too short for a header");
  std::string bad_magic = good;
  bad_magic[0] = 'X';
  EXPECT_NE(ParseError(bad_magic).find("cb.bin: not a valid retrieval codebook: wrong magic"),
            std::string::npos);
  EXPECT_NE(ParseError(good.substr(0, good.size() - 1)).find("truncated"), std::string::npos);
  EXPECT_NE(ParseError(good + "x").find("size is 57 bytes, expected 56"), std::string::npos);
  std::string flipped = good;
  flipped[30] ^= 0x10;
  EXPECT_NE(ParseError(flipped).find("checksum mismatch"), std::string::npos);

  testing::TemporaryDir dir;
  try {
    ReadCodebook(dir.path() / "missing.bin");
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              (dir.path() / "missing.bin").string() +
                  ": retrieval codebook not found (train one with `tessera vocab`)");
  }
}

// Every truncation and every single-bit flip of a valid file is refused with an
// InputError; none crashes or is accepted.
TEST(RetrievalCodebook, FuzzedFilesAreRefusedNeverAccepted) {
  Codebook codebook;
  codebook.descriptor_dimension = 8;
  codebook.num_centers = 4;
  std::mt19937 random(3);
  for (int i = 0; i < 32; ++i) codebook.centers.push_back(static_cast<float>(random() % 1000) / 7);
  const std::string good = SerializeCodebook(codebook);
  size_t refused = 0;
  for (size_t length = 0; length < good.size(); ++length) {
    EXPECT_THROW(ParseCodebook(good.substr(0, length), "f"), InputError) << length;
    ++refused;
  }
  for (size_t byte = 0; byte < good.size(); ++byte) {
    for (int bit = 0; bit < 8; ++bit) {
      std::string flipped = good;
      flipped[byte] = static_cast<char>(flipped[byte] ^ (1 << bit));
      EXPECT_THROW(ParseCodebook(flipped, "f"), InputError) << byte << ":" << bit;
      ++refused;
    }
  }
  EXPECT_EQ(refused, good.size() * 9);
  // Random garbage of the right size too.
  for (int trial = 0; trial < 200; ++trial) {
    std::string garbage = good;
    for (size_t i = 8; i < garbage.size(); ++i) garbage[i] = static_cast<char>(random());
    EXPECT_THROW(ParseCodebook(garbage, "f"), InputError);
  }
}

}  // namespace
}  // namespace tessera::retrieval
