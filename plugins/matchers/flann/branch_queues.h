#pragma once

// The two priority queues of branches that KMeansTree searches with. Exploring a node of
// the k-means tree ranks its children (the distance to a child's centre less cb_index
// times its variance); all but the nearest wait in the queue, and the search goes on
// from the lowest rank in it.
//
// FlannBranchQueue is FLANN's: every child goes into one binary heap (std::push_heap,
// FLANN's comparison), so even branches tied in rank leave in FLANN's order. With a
// branching of 32 that is 31 heap insertions per node explored, most of a search's time,
// for branches that are mostly never taken.
//
// BlockBranchQueue keeps the children of each explored node together in a block, and the
// heap holds one entry per block: the lowest rank left in it. When no two waiting branches
// share the lowest rank, the lowest is one branch, and both queues hand out the same
// branch. When two do, FLANN's heap order decides between them, which this queue does not
// know: it reports the tie, and the search starts again with FlannBranchQueue. It does the
// same where FLANN's queue would be full and drop a branch.

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "vectorized_l2.h"  // flann_l2::internal::HasAvx2, <immintrin.h>

namespace tessera::flann_kmeans {

namespace internal {

#if defined(__x86_64__)
// The lowest of `width` (a multiple of 8) floats, eight lanes at a time. Exact: min
// rounds nothing, and the ranks hold no NaN.
__attribute__((target("avx2"))) inline float AvxLowest(const float* values, size_t width) {
  __m256 lowest = _mm256_loadu_ps(values);
  for (size_t i = 8; i < width; i += 8) lowest = _mm256_min_ps(lowest, _mm256_loadu_ps(values + i));
  __m128 half = _mm_min_ps(_mm256_castps256_ps128(lowest), _mm256_extractf128_ps(lowest, 1));
  half = _mm_min_ps(half, _mm_movehl_ps(half, half));
  half = _mm_min_ss(half, _mm_shuffle_ps(half, half, 1));
  return _mm_cvtss_f32(half);
}

// The first of `width` (a multiple of 8) floats equal to `value`; `width` if none is.
__attribute__((target("avx2"))) inline size_t AvxFind(const float* values, size_t width,
                                                      float value) {
  const __m256 wanted = _mm256_set1_ps(value);
  for (size_t i = 0; i < width; i += 8) {
    const int mask =
        _mm256_movemask_ps(_mm256_cmp_ps(_mm256_loadu_ps(values + i), wanted, _CMP_EQ_OQ));
    if (mask != 0) return i + static_cast<size_t>(__builtin_ctz(static_cast<unsigned>(mask)));
  }
  return width;
}

#endif

inline float Lowest(const float* values, size_t width) {
#if defined(__x86_64__)
  if (flann_l2::internal::HasAvx2()) return AvxLowest(values, width);
#endif
  float lowest = values[0];
  for (size_t i = 1; i < width; ++i) lowest = std::min(lowest, values[i]);
  return lowest;
}

inline size_t Find(const float* values, size_t width, float value) {
#if defined(__x86_64__)
  if (flann_l2::internal::HasAvx2()) return AvxFind(values, width, value);
#endif
  return static_cast<size_t>(std::find(values, values + width, value) - values);
}

}  // namespace internal

// A rank and a number (a node, or a block), packed into one 64-bit word: a heap then moves
// an entry with one load and one store, which the CPU forwards from store to load.
class RankedEntry {
 public:
  RankedEntry() = default;
  RankedEntry(float rank, uint32_t id) {
    uint32_t rank_bits;
    std::memcpy(&rank_bits, &rank, sizeof(rank_bits));
    bits_ = (static_cast<uint64_t>(id) << 32) | rank_bits;
  }
  float rank() const {
    const auto rank_bits = static_cast<uint32_t>(bits_);
    float value;
    std::memcpy(&value, &rank_bits, sizeof(value));
    return value;
  }
  uint32_t id() const { return static_cast<uint32_t>(bits_ >> 32); }

 private:
  uint64_t bits_ = 0;
};

// FLANN's Heap<BranchSt> order: std::push_heap / pop_heap with "greater" on the rank.
struct RanksAfter {
  bool operator()(const RankedEntry& a, const RankedEntry& b) const { return b.rank() < a.rank(); }
};

enum class PopResult { kEmpty, kBranch, kTie };

class FlannBranchQueue {
 public:
  // Empty, for a tree of `num_nodes` nodes over `capacity` rows (FLANN's bound).
  void Reset(size_t num_nodes, size_t capacity) {
    capacity_ = capacity;
    if (heap_.size() < capacity) heap_.resize(capacity);
    if (centre_distances_.size() < num_nodes) centre_distances_.resize(num_nodes);
    size_ = 0;
  }

  // The children first .. first + count - 1 of an explored node but `best`, in FLANN's
  // order (ascending child). Never refuses.
  bool AddChildren(uint32_t first, uint32_t count, uint32_t best, const float* ranks,
                   const float* centre_distances) {
    RankedEntry* const heap = heap_.data();
    size_t size = size_;
    for (uint32_t i = 0; i < count; ++i) {
      if (i == best || size == capacity_) continue;  // FLANN drops a branch when full
      centre_distances_[first + i] = centre_distances[i];
      heap[size++] = RankedEntry(ranks[i], first + i);
      std::push_heap(heap, heap + size, RanksAfter());
    }
    size_ = size;
    return true;
  }

  PopResult Pop(uint32_t* node, float* centre_distance) {
    if (size_ == 0) return PopResult::kEmpty;
    *node = heap_[0].id();
    *centre_distance = centre_distances_[*node];
    std::pop_heap(heap_.data(), heap_.data() + size_, RanksAfter());
    --size_;
    return PopResult::kBranch;
  }

 private:
  std::vector<RankedEntry> heap_;        // the first size_ entries
  std::vector<float> centre_distances_;  // per node, while it waits
  size_t size_ = 0;
  size_t capacity_ = 0;
};

class BlockBranchQueue {
 public:
  // Empty, for a tree of `branching` children per inner node over `capacity` rows.
  void Reset(size_t branching, size_t capacity) {
    width_ = (branching + 7) / 8 * 8;
    capacity_ = capacity;
    num_blocks_ = 0;
    waiting_ = 0;
    heap_.clear();
  }

  // As FlannBranchQueue::AddChildren; false where FLANN's queue would drop a branch.
  bool AddChildren(uint32_t first, uint32_t count, uint32_t best, const float* ranks,
                   const float* centre_distances) {
    if (count == 0 || count > width_) return false;
    if (waiting_ + (count - 1) > capacity_) return false;
    waiting_ += count - 1;
    const size_t block = num_blocks_++;
    if (ranks_.size() < num_blocks_ * width_) {
      ranks_.resize(num_blocks_ * width_ * 2);
      centre_distances_.resize(ranks_.size());
      first_.resize(num_blocks_ * 2);
    }
    float* const block_ranks = ranks_.data() + block * width_;
    std::copy(ranks, ranks + count, block_ranks);
    std::fill(block_ranks + count, block_ranks + width_, kGone);
    block_ranks[best] = kGone;
    std::copy(centre_distances, centre_distances + count,
              centre_distances_.data() + block * width_);
    first_[block] = first;
    const float lowest = internal::Lowest(block_ranks, width_);
    if (lowest != kGone) {
      heap_.push_back(RankedEntry(lowest, static_cast<uint32_t>(block)));
      std::push_heap(heap_.begin(), heap_.end(), RanksAfter());
    }
    return true;
  }

  // The waiting branch of the lowest rank; kTie where another has the same rank.
  PopResult Pop(uint32_t* node, float* centre_distance) {
    if (heap_.empty()) return PopResult::kEmpty;
    const float rank = heap_[0].rank();
    const uint32_t block = heap_[0].id();
    float* const block_ranks = ranks_.data() + static_cast<size_t>(block) * width_;
    const size_t child = internal::Find(block_ranks, width_, rank);
    if (child == width_) return PopResult::kTie;  // cannot be: start again in FLANN's order
    *node = first_[block] + static_cast<uint32_t>(child);
    *centre_distance = centre_distances_[static_cast<size_t>(block) * width_ + child];
    block_ranks[child] = kGone;
    --waiting_;
    const float lowest = internal::Lowest(block_ranks, width_);
    if (lowest == kGone) {
      std::pop_heap(heap_.begin(), heap_.end(), RanksAfter());
      heap_.pop_back();
    } else {
      heap_[0] = RankedEntry(lowest, block);
      SiftDownTop();
    }
    return !heap_.empty() && heap_[0].rank() == rank ? PopResult::kTie : PopResult::kBranch;
  }

 private:
  static constexpr float kGone = std::numeric_limits<float>::infinity();

  // Restores the heap after its top entry's rank grew.
  void SiftDownTop() {
    const size_t size = heap_.size();
    size_t at = 0;
    const RankedEntry moving = heap_[0];
    for (;;) {
      size_t child = 2 * at + 1;
      if (child >= size) break;
      if (child + 1 < size && heap_[child + 1].rank() < heap_[child].rank()) ++child;
      if (!(heap_[child].rank() < moving.rank())) break;
      heap_[at] = heap_[child];
      at = child;
    }
    heap_[at] = moving;
  }

  size_t width_ = 8;     // ranks per block: the branching rounded up to a multiple of 8
  size_t capacity_ = 0;  // FLANN's bound on waiting branches
  size_t waiting_ = 0;   // branches waiting, as FLANN's queue would count them
  size_t num_blocks_ = 0;
  std::vector<float> ranks_;             // per block: its children's ranks, kGone once taken
  std::vector<float> centre_distances_;  // per block: the distances to its children's centres
  std::vector<uint32_t> first_;          // per block: its first child
  std::vector<RankedEntry> heap_;        // a block's lowest rank left; one entry per block
};

}  // namespace tessera::flann_kmeans
