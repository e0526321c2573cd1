#pragma once

#include <cstddef>
#include <cstdint>

namespace tessera {

// A non-owning view of an 8-bit single-channel (grey) image in row-major order.
struct ImageView {
  int width = 0;
  int height = 0;
  size_t stride = 0;  // bytes from one row to the next
  const uint8_t* data = nullptr;

  const uint8_t* Row(int y) const { return data + static_cast<size_t>(y) * stride; }
};

}  // namespace tessera
