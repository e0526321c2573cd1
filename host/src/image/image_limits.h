#pragma once

// Limits on input images that the scan enforces and the manifest can change.

#include <cstdint>

namespace tessera {

// Images of more pixels are refused before decoding (manifest `max_image_pixels`): a
// 250-megapixel image takes 750 MB decoded, and a forged header can claim far more.
inline constexpr int64_t kDefaultMaxImagePixels = 250'000'000;

}  // namespace tessera
