#pragma once

// FLANN's hierarchical k-means tree (KMeansIndex), copied into flat arrays and searched
// the way KMeansIndex::findNeighbors searches it: the same branches in the same order,
// the same pruning, the same count of checks and FLANN's own result set and priority
// queue order, hence the same neighbours and distances, bit for bit.
//
// What differs is the bookkeeping around the search. FLANN pushes every child but the
// nearest of each node it explores into one binary heap, most of them never taken; for
// every query it allocates that heap with room for the whole data set, for every node a
// vector of distances, and it computes the distance to a branch's centre twice. Its
// leaves point to descriptors scattered over the data set. Here the queue holds one
// entry per explored node (BlockBranchQueue, branch_queues.h: a query that meets tied
// branches is searched again with FLANN's heap order), is reused from query to query and
// keeps each branch's centre distance; the children of a node and the descriptors of a
// leaf lie side by side, and the distances run in vector registers.
//
// The tree is read through KMeansIndex::serialize, FLANN's public saving interface, with
// an archive that records the values instead of writing bytes. When what it records is
// not the layout this file expects (another FLANN version), `FromIndex` returns nothing
// and the caller keeps searching with FLANN.

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <flann/flann.hpp>
#include <memory>
#include <type_traits>
#include <vector>

#include "branch_queues.h"
#include "vectorized_l2.h"

namespace tessera::flann_kmeans {

namespace internal {

class NearestTwo;  // the result set of one query

template <typename T>
struct IsNNIndex : std::false_type {};
template <typename Distance>
struct IsNNIndex<flann::NNIndex<Distance>> : std::true_type {};

// A saving archive for KMeansIndex::serialize that keeps the tree's values in the order
// they are written: the index's parameters, then each node depth first (centre, radius,
// variance, size, number of children, then the leaf's point indices or the children).
// The NNIndex base (header, data set, ids) is skipped.
class TreeRecorder : public flann::serialization::OutputArchive<TreeRecorder> {
 public:
  enum class Kind { kInt, kFloat, kSize, kBinary };
  struct Value {
    Kind kind;
    double number;  // kInt, kFloat, kSize
    size_t offset;  // kBinary: into bytes()
    size_t length;  // kBinary
  };

  template <typename T>
  TreeRecorder& operator&(const T& value) {
    if constexpr (!IsNNIndex<T>::value) {
      flann::serialization::Serializer<T>::save(*this, value);
    }
    return *this;
  }

  void save(int value) { values_.push_back({Kind::kInt, static_cast<double>(value), 0, 0}); }
  void save(float value) { values_.push_back({Kind::kFloat, static_cast<double>(value), 0, 0}); }
  void save(unsigned long value) {
    values_.push_back({Kind::kSize, static_cast<double>(value), 0, 0});
  }
  // Anything else is not part of the layout this file reads.
  template <typename T>
  void save(const T&) {
    unexpected_ = true;
  }
  void save_binary(const void* data, size_t length) {
    values_.push_back({Kind::kBinary, 0.0, bytes_.size(), length});
    const auto* begin = static_cast<const uint8_t*>(data);
    bytes_.insert(bytes_.end(), begin, begin + length);
  }

  const std::vector<Value>& values() const { return values_; }
  const std::vector<uint8_t>& bytes() const { return bytes_; }
  bool unexpected() const { return unexpected_; }

 private:
  std::vector<Value> values_;
  std::vector<uint8_t> bytes_;
  bool unexpected_ = false;
};

}  // namespace internal

// What one thread reuses from query to query.
struct SearchScratch {
  std::vector<float> query;            // the query's bytes as floats
  std::vector<float> distances;        // to the centres of the children of the node explored
  std::vector<float> ranks;            // of those children
  std::vector<int32_t> row_distances;  // to the rows of the leaf visited
  BlockBranchQueue blocks;
  FlannBranchQueue flann;
  // Queries searched, and how many of them again with FLANN's queue after a tie.
  size_t searches = 0;
  size_t searches_again = 0;
};

class KMeansTree {
 public:
  // The tree of `index` (built over `rows` descriptors of `dimension` bytes at `data`,
  // row after row), or nothing when it cannot be read.
  template <typename Distance>
  static std::unique_ptr<KMeansTree> FromIndex(const flann::KMeansIndex<Distance>& index,
                                               const uint8_t* data, size_t rows, size_t dimension);

  // The k (1 or 2) nearest rows of `query` after at most `max_checks` leaf rows (FLANN's
  // `checks`, at least 1), nearest first: `indices` and squared `distances`, k entries
  // each, -1 and the largest float where fewer were found. Returns how many were found.
  size_t Search(const uint8_t* query, size_t k, int max_checks, SearchScratch* scratch,
                int* indices, float* distances) const;

  // Whether `rows` rows of `dimension` bytes at `data` are the rows the tree was copied
  // with, byte for byte.
  bool HoldsRows(const uint8_t* data, size_t rows, size_t dimension) const;

  size_t Bytes() const {
    return nodes_.size() * sizeof(Node) + (centres_.size() + variances_.size()) * sizeof(float) +
           leaf_rows_.size() + leaf_ids_.size() * sizeof(uint32_t);
  }

 private:
  struct Node {
    float radius;
    uint32_t first;  // first child (inner node) or first leaf row (leaf)
    uint32_t count;  // children or leaf rows
    bool leaf;
  };

  // A node as read from the recorder, before it is laid out.
  struct ReadNode {
    size_t centre_offset;  // into the recorder's bytes
    float radius;
    float variance;
    std::vector<size_t> children;  // into the list of read nodes
    std::vector<size_t> rows;
  };

  bool Read(const internal::TreeRecorder& recorder, size_t rows, size_t dimension,
            const uint8_t* data);
  // One search with `queue`; false when the queue gives up (BlockBranchQueue on a tie).
  template <typename Queue>
  bool SearchWith(Queue* queue, const uint8_t* query, int max_checks, internal::NearestTwo* result,
                  SearchScratch* scratch) const;
  // FLANN's findNN from `node`: false when the queue gives up.
  template <typename Queue>
  bool Descend(uint32_t node, float centre_distance, const uint8_t* query, int max_checks,
               int* checks, internal::NearestTwo* result, Queue* queue,
               SearchScratch* scratch) const;
  const float* Centre(uint32_t node) const { return centres_.data() + node * dimension_; }

  size_t dimension_ = 0;
  size_t rows_ = 0;
  size_t branching_ = 0;
  size_t largest_leaf_ = 0;  // rows
  float cb_index_ = 0.0f;
  std::vector<Node> nodes_;         // breadth first: a node's children are consecutive
  std::vector<float> variances_;    // node i's at i
  std::vector<float> centres_;      // node i's at i * dimension_
  std::vector<uint8_t> leaf_rows_;  // the descriptors, leaf after leaf
  std::vector<uint32_t> leaf_ids_;  // their rows in the data set
};

template <typename Distance>
std::unique_ptr<KMeansTree> KMeansTree::FromIndex(const flann::KMeansIndex<Distance>& index,
                                                  const uint8_t* data, size_t rows,
                                                  size_t dimension) {
  static_assert(std::is_same_v<Distance, flann_l2::VectorizedL2Uint8>,
                "the search computes VectorizedL2Uint8's distances, float centres");
  if (rows == 0 || rows > UINT32_MAX || index.size() != rows || index.veclen() != dimension) {
    return nullptr;
  }
  internal::TreeRecorder recorder;
  // serialize is not const, but saving only reads.
  const_cast<flann::KMeansIndex<Distance>&>(index).serialize(recorder);
  auto tree = std::make_unique<KMeansTree>();
  if (recorder.unexpected() || !tree->Read(recorder, rows, dimension, data)) return nullptr;
  return tree;
}

}  // namespace tessera::flann_kmeans
