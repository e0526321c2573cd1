#include "vectorized_l2.h"

#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <vector>

namespace tessera::flann_l2 {
namespace {

// Bitwise equality: the kernels must give the reference's float, not a close one.
bool SameBits(float a, float b) { return std::memcmp(&a, &b, sizeof(float)) == 0; }

template <typename Centre>
void ExpectKernelsMatchTheReference(uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> byte(0, 255);
  std::uniform_real_distribution<double> centre(-10.0, 265.0);
  for (const size_t size :
       {size_t{0}, size_t{3}, size_t{8}, size_t{61}, size_t{64}, size_t{128}, size_t{131}}) {
    for (int trial = 0; trial < 200; ++trial) {
      std::vector<uint8_t> a(size);
      std::vector<Centre> b(size);
      for (size_t i = 0; i < size; ++i) {
        a[i] = static_cast<uint8_t>(byte(rng));
        // Centres with many significant bits, where a different order of additions or a
        // fused multiply-add would round differently.
        b[i] = static_cast<Centre>(centre(rng));
      }
      const float reference = ScalarL2ToCentre(a.data(), b.data(), size);
      ASSERT_TRUE(SameBits(L2ToCentre(a.data(), b.data(), size), reference))
          << size << " dimensions";
#if defined(__x86_64__)
      ASSERT_TRUE(SameBits(internal::SseL2ToCentre(a.data(), b.data(), size), reference))
          << size << " dimensions";
      if (internal::HasAvx2()) {
        ASSERT_TRUE(SameBits(internal::AvxL2ToCentre(a.data(), b.data(), size), reference))
            << size << " dimensions";
      }
#endif
      // Either argument order, as FLANN calls it.
      const VectorizedL2Uint8 distance;
      ASSERT_TRUE(SameBits(distance(a.data(), b.data(), size), reference));
      ASSERT_TRUE(SameBits(distance(b.data(), a.data(), size), reference));
    }
  }
}

TEST(VectorizedL2, KernelsGiveTheReferenceBitsForFloatCentres) {
  ExpectKernelsMatchTheReference<float>(1);
}

TEST(VectorizedL2, KernelsGiveTheReferenceBitsForDoubleCentres) {
  ExpectKernelsMatchTheReference<double>(2);
}

// Several centres at once (four at a time, then one by one) give each centre's bits.
TEST(VectorizedL2, CentresInBatchesGiveEachCentresBits) {
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> byte(0, 255);
  std::uniform_real_distribution<float> centre(-10.0f, 265.0f);
  for (const size_t size : {size_t{3}, size_t{8}, size_t{61}, size_t{128}}) {
    for (size_t count = 0; count <= 9; ++count) {
      std::vector<uint8_t> a(size);
      std::vector<float> a_float(size), centres(count * size), out(count);
      for (size_t i = 0; i < size; ++i) {
        a[i] = static_cast<uint8_t>(byte(rng));
        a_float[i] = a[i];
      }
      for (float& value : centres) value = centre(rng);
      L2ToCentres(a.data(), a_float.data(), centres.data(), count, size, out.data());
      for (size_t c = 0; c < count; ++c) {
        ASSERT_TRUE(SameBits(out[c], ScalarL2ToCentre(a.data(), centres.data() + c * size, size)))
            << size << " dimensions, centre " << c << " of " << count;
      }
    }
  }
}

TEST(VectorizedL2, BytesKernelsAreExact) {
  std::mt19937 rng(4);
  std::uniform_int_distribution<int> byte(0, 255);
  for (const size_t size :
       {size_t{0}, size_t{5}, size_t{16}, size_t{31}, size_t{128}, size_t{131}}) {
    std::vector<uint8_t> a(size), b(size);
    for (size_t i = 0; i < size; ++i) {
      a[i] = static_cast<uint8_t>(byte(rng));
      b[i] = static_cast<uint8_t>(byte(rng));
    }
    int32_t expected = 0;
    for (size_t i = 0; i < size; ++i) expected += (a[i] - b[i]) * (a[i] - b[i]);
    EXPECT_EQ(ScalarL2Bytes(a.data(), b.data(), size), expected) << size;
    EXPECT_EQ(L2Bytes(a.data(), b.data(), size), expected) << size;
#if defined(__x86_64__)
    if (internal::HasAvx2()) {
      EXPECT_EQ(internal::AvxL2Bytes(a.data(), b.data(), size), expected) << size;
    }
#endif
  }
}

TEST(VectorizedL2, BytesAgainstBytesAreExact) {
  std::vector<uint8_t> a(128, 255), b(128, 0);
  EXPECT_EQ(VectorizedL2Uint8()(a.data(), b.data(), a.size()), 128.0f * 255 * 255);
  a[5] = 3;
  b[5] = 1;
  EXPECT_EQ(VectorizedL2Uint8()(a.data(), b.data(), a.size()), 127.0f * 255 * 255 + 4);
}

}  // namespace
}  // namespace tessera::flann_l2
