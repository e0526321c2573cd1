#pragma once

#include <cstddef>

#include "image/image_entry.h"

namespace tessera {

// Reads the EXIF block of a JPEG file held in memory (or of raw EXIF data starting
// with "Exif\0\0"). Data without EXIF, or with a damaged block, gives the defaults:
// EXIF is optional, so a bad block never makes an image unusable.
ExifInfo ReadExifInfo(const unsigned char* data, size_t size);

// Whether an EXIF orientation (1..8) turns the image by 90 degrees, swapping width
// and height.
inline bool OrientationSwapsAxes(int orientation) { return orientation >= 5 && orientation <= 8; }

}  // namespace tessera
