#pragma once

// A VLAD codebook: k cluster centres in the space of (RootSIFT-converted) local
// descriptors, and the file format that `tessera vocab` writes and the retrieval
// selector's `codebook` option reads. All numbers little-endian:
//
//   offset  size     field
//   0       8        magic "TSRVLAD\0"
//   8       4        uint32 format version (1)
//   12      4        uint32 descriptor dimension d (bytes per workspace descriptor row)
//   16      4        uint32 descriptor metric (0 = l2; the only one VLAD accepts)
//   20      4        uint32 number of centres k
//   24      4*k*d    float32 centres, row-major, one centre per row
//   24+4kd  8        uint64 FNV-1a hash of every byte before it
//
// A file of any other size, magic, version, metric, hash or with a non-finite centre is
// refused with an InputError naming the file.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "tessera/features.h"

namespace tessera::retrieval {

struct Codebook {
  int descriptor_dimension = 0;
  DescriptorMetric metric = DescriptorMetric::kL2;
  int num_centers = 0;
  std::vector<float> centers;  // num_centers x descriptor_dimension, row-major
};

inline constexpr uint32_t kCodebookFormatVersion = 1;
inline constexpr size_t kCodebookHeaderBytes = 24;

// The file's bytes, and back. Parse throws InputError prefixed with `source` (the file).
std::string SerializeCodebook(const Codebook& codebook);
Codebook ParseCodebook(const std::string& bytes, const std::string& source);

void WriteCodebook(const Codebook& codebook, const std::filesystem::path& path);
Codebook ReadCodebook(const std::filesystem::path& path);

}  // namespace tessera::retrieval
