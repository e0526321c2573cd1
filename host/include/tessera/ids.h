#pragma once

#include <cstdint>
#include <limits>
#include <utility>

namespace tessera {

// Typed ids, as in COLMAP's database: each has an invalid sentinel.
using camera_t = uint32_t;
using image_t = uint32_t;
using point2D_t = uint32_t;
using point3D_t = uint64_t;
// pair_id = image_id1 * kMaxNumImages + image_id2 with image_id1 < image_id2.
using image_pair_t = uint64_t;

constexpr camera_t kInvalidCameraId = std::numeric_limits<camera_t>::max();
constexpr image_t kInvalidImageId = std::numeric_limits<image_t>::max();
constexpr point2D_t kInvalidPoint2DIdx = std::numeric_limits<point2D_t>::max();
constexpr point3D_t kInvalidPoint3DId = std::numeric_limits<point3D_t>::max();
constexpr image_pair_t kInvalidImagePairId = std::numeric_limits<image_pair_t>::max();

// COLMAP's limit on image ids, which its pair ids are built from.
constexpr uint64_t kMaxNumImages = 2147483647;

inline image_pair_t ImagePairToPairId(image_t image_id1, image_t image_id2) {
  if (image_id1 > image_id2) std::swap(image_id1, image_id2);
  return kMaxNumImages * image_id1 + image_id2;
}

inline std::pair<image_t, image_t> PairIdToImagePair(image_pair_t pair_id) {
  const auto image_id2 = static_cast<image_t>(pair_id % kMaxNumImages);
  const auto image_id1 = static_cast<image_t>((pair_id - image_id2) / kMaxNumImages);
  return {image_id1, image_id2};
}

// Whether a pair given as (image_id1, image_id2) is stored swapped in a pair id.
inline bool SwapImagePair(image_t image_id1, image_t image_id2) { return image_id1 > image_id2; }

}  // namespace tessera
