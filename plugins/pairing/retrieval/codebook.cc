#include "codebook.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>

#include "tessera/errors.h"

namespace tessera::retrieval {
namespace {

constexpr char kMagic[8] = {'T', 'S', 'R', 'V', 'L', 'A', 'D', '\0'};
// Bounds that keep a forged header from asking for absurd allocations.
constexpr uint32_t kMaxDimension = 4096;
constexpr uint32_t kMaxCenters = 1u << 16;

uint64_t Fnv1a(const char* data, size_t size) {
  uint64_t hash = 14695981039346656037ull;
  for (size_t i = 0; i < size; ++i) {
    hash ^= static_cast<uint8_t>(data[i]);
    hash *= 1099511628211ull;
  }
  return hash;
}

void AppendUint32(std::string& out, uint32_t value) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((value >> (8 * i)) & 0xff));
}

void AppendUint64(std::string& out, uint64_t value) {
  for (int i = 0; i < 8; ++i) out.push_back(static_cast<char>((value >> (8 * i)) & 0xff));
}

uint64_t ReadUint(const std::string& bytes, size_t offset, int size) {
  uint64_t value = 0;
  for (int i = 0; i < size; ++i) {
    value |= static_cast<uint64_t>(static_cast<uint8_t>(bytes[offset + i])) << (8 * i);
  }
  return value;
}

}  // namespace

std::string SerializeCodebook(const Codebook& codebook) {
  const size_t num_values = static_cast<size_t>(codebook.num_centers) *
                            static_cast<size_t>(codebook.descriptor_dimension);
  if (codebook.num_centers <= 0 || codebook.descriptor_dimension <= 0 ||
      codebook.centers.size() != num_values) {
    throw std::logic_error("SerializeCodebook: centers do not match num_centers x dimension");
  }
  std::string out(kMagic, sizeof(kMagic));
  AppendUint32(out, kCodebookFormatVersion);
  AppendUint32(out, static_cast<uint32_t>(codebook.descriptor_dimension));
  AppendUint32(out, static_cast<uint32_t>(codebook.metric));
  AppendUint32(out, static_cast<uint32_t>(codebook.num_centers));
  for (const float value : codebook.centers) {
    uint32_t bits = 0;
    std::memcpy(&bits, &value, sizeof(bits));
    AppendUint32(out, bits);
  }
  AppendUint64(out, Fnv1a(out.data(), out.size()));
  return out;
}

Codebook ParseCodebook(const std::string& bytes, const std::string& source) {
  const auto fail = [&](const std::string& why) -> InputError {
    return InputError(source + ": not a valid retrieval codebook: " + why);
  };
  if (bytes.size() < kCodebookHeaderBytes + 8) throw fail("file is too short for a header");
  if (std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0) {
    throw fail("wrong magic (expected a file written by `tessera vocab`)");
  }
  const uint64_t version = ReadUint(bytes, 8, 4);
  if (version != kCodebookFormatVersion) {
    throw fail("format version " + std::to_string(version) + " is not supported (expected " +
               std::to_string(kCodebookFormatVersion) + ")");
  }
  const uint64_t dimension = ReadUint(bytes, 12, 4);
  const uint64_t metric = ReadUint(bytes, 16, 4);
  const uint64_t num_centers = ReadUint(bytes, 20, 4);
  if (dimension == 0 || dimension > kMaxDimension) {
    throw fail("descriptor dimension " + std::to_string(dimension) + " is out of range");
  }
  if (metric != static_cast<uint64_t>(DescriptorMetric::kL2)) {
    throw fail("descriptor metric " + std::to_string(metric) + " is not l2");
  }
  if (num_centers == 0 || num_centers > kMaxCenters) {
    throw fail("number of centres " + std::to_string(num_centers) + " is out of range");
  }
  const size_t expected_size = kCodebookHeaderBytes + 4 * num_centers * dimension + 8;
  if (bytes.size() != expected_size) {
    throw fail("size is " + std::to_string(bytes.size()) + " bytes, expected " +
               std::to_string(expected_size) + " for " + std::to_string(num_centers) +
               " centres of dimension " + std::to_string(dimension) + " (truncated?)");
  }
  const size_t hash_offset = expected_size - 8;
  if (ReadUint(bytes, hash_offset, 8) != Fnv1a(bytes.data(), hash_offset)) {
    throw fail("checksum mismatch (the file is corrupt)");
  }
  Codebook codebook;
  codebook.descriptor_dimension = static_cast<int>(dimension);
  codebook.metric = DescriptorMetric::kL2;
  codebook.num_centers = static_cast<int>(num_centers);
  codebook.centers.resize(num_centers * dimension);
  for (size_t i = 0; i < codebook.centers.size(); ++i) {
    const uint32_t bits = static_cast<uint32_t>(ReadUint(bytes, kCodebookHeaderBytes + 4 * i, 4));
    std::memcpy(&codebook.centers[i], &bits, sizeof(bits));
    if (!std::isfinite(codebook.centers[i])) throw fail("a centre is not finite");
  }
  return codebook;
}

void WriteCodebook(const Codebook& codebook, const std::filesystem::path& path) {
  const std::string bytes = SerializeCodebook(codebook);
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  if (!file) throw InputError(path.string() + ": cannot open for writing");
  file.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  file.close();
  if (!file) throw InputError(path.string() + ": cannot write the codebook");
}

Codebook ReadCodebook(const std::filesystem::path& path) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    throw InputError(path.string() +
                     ": retrieval codebook not found (train one with `tessera vocab`)");
  }
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError(path.string() + ": cannot open the retrieval codebook");
  std::ostringstream contents;
  contents << file.rdbuf();
  return ParseCodebook(contents.str(), path.string());
}

}  // namespace tessera::retrieval
