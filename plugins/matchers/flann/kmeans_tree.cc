#include "kmeans_tree.h"

#include <limits>

namespace tessera::flann_kmeans {

namespace {

using Kind = internal::TreeRecorder::Kind;

// Reads the recorder's values in order; any value of another kind fails the read.
class ValueReader {
 public:
  explicit ValueReader(const internal::TreeRecorder& recorder) : recorder_(recorder) {}

  bool Next(Kind kind, double* number) {
    if (at_ >= recorder_.values().size() || recorder_.values()[at_].kind != kind) return false;
    *number = recorder_.values()[at_++].number;
    return true;
  }
  bool NextBinary(size_t length, size_t* offset) {
    if (at_ >= recorder_.values().size()) return false;
    const internal::TreeRecorder::Value& value = recorder_.values()[at_];
    if (value.kind != Kind::kBinary || value.length != length) return false;
    *offset = value.offset;
    ++at_;
    return true;
  }
  bool AtEnd() const { return at_ == recorder_.values().size(); }

 private:
  const internal::TreeRecorder& recorder_;
  size_t at_ = 0;
};

}  // namespace

// FLANN's KNNSimpleResultSet (without FLANN_FIRST_MATCH) for at most two neighbours,
// without its heap-allocated storage: the same insertions, the same worst distance.
class internal::NearestTwo {
 public:
  explicit NearestTwo(size_t capacity) : capacity_(capacity) { distances_[capacity_ - 1] = worst_; }
  bool Full() const { return count_ == capacity_; }
  float Worst() const { return worst_; }
  size_t Count() const { return count_; }
  float Distance(size_t i) const { return distances_[i]; }
  uint32_t Index(size_t i) const { return indices_[i]; }

  void Add(float distance, uint32_t index) {
    if (distance >= worst_) return;
    if (count_ < capacity_) ++count_;
    size_t i = count_ - 1;
    for (; i > 0; --i) {
      if (distances_[i - 1] > distance) {
        distances_[i] = distances_[i - 1];
        indices_[i] = indices_[i - 1];
      } else {
        break;
      }
    }
    distances_[i] = distance;
    indices_[i] = index;
    worst_ = distances_[capacity_ - 1];
  }

 private:
  size_t capacity_;
  size_t count_ = 0;
  float worst_ = std::numeric_limits<float>::max();
  float distances_[2] = {std::numeric_limits<float>::max(), std::numeric_limits<float>::max()};
  uint32_t indices_[2] = {0, 0};
};

bool KMeansTree::Read(const internal::TreeRecorder& recorder, size_t rows, size_t dimension,
                      const uint8_t* data) {
  ValueReader reader(recorder);
  double branching = 0, iterations = 0, memory = 0, cb_index = 0, centers_init = 0;
  if (!reader.Next(Kind::kInt, &branching) || !reader.Next(Kind::kInt, &iterations) ||
      !reader.Next(Kind::kInt, &memory) || !reader.Next(Kind::kFloat, &cb_index) ||
      !reader.Next(Kind::kInt, &centers_init) || branching < 2) {
    return false;
  }
  // The nodes depth first, as written; a node's children are read after it.
  std::vector<ReadNode> read;
  std::vector<char> row_seen(rows, 0);
  size_t rows_seen = 0;
  // One entry per node still to read: its parent (SIZE_MAX for the root). The top of
  // the stack is read next, so a node's subtree is read before its next sibling.
  std::vector<size_t> pending = {SIZE_MAX};
  while (!pending.empty()) {
    const size_t parent = pending.back();
    pending.pop_back();
    ReadNode node;
    double radius = 0, variance = 0, size = 0, num_children = 0;
    if (!reader.NextBinary(dimension * sizeof(float), &node.centre_offset) ||
        !reader.Next(Kind::kFloat, &radius) || !reader.Next(Kind::kFloat, &variance) ||
        !reader.Next(Kind::kInt, &size) || !reader.Next(Kind::kSize, &num_children)) {
      return false;
    }
    node.radius = static_cast<float>(radius);
    node.variance = static_cast<float>(variance);
    const size_t id = read.size();
    if (parent != SIZE_MAX) read[parent].children.push_back(id);
    if (num_children == 0) {
      double num_rows = 0;
      if (!reader.Next(Kind::kSize, &num_rows)) return false;
      for (size_t i = 0; i < static_cast<size_t>(num_rows); ++i) {
        double row = 0;
        if (!reader.Next(Kind::kSize, &row) || row >= static_cast<double>(rows) ||
            row_seen[static_cast<size_t>(row)]) {
          return false;
        }
        row_seen[static_cast<size_t>(row)] = 1;
        ++rows_seen;
        node.rows.push_back(static_cast<size_t>(row));
      }
    } else if (num_children != branching) {
      return false;  // FLANN's search assumes `branching` children
    } else {
      pending.insert(pending.end(), static_cast<size_t>(num_children), id);
    }
    read.push_back(std::move(node));
  }
  if (!reader.AtEnd() || rows_seen != rows) return false;

  // Breadth first, so that the children of a node are consecutive.
  dimension_ = dimension;
  rows_ = rows;
  branching_ = static_cast<size_t>(branching);
  cb_index_ = static_cast<float>(cb_index);
  std::vector<size_t> order = {0};
  nodes_.clear();
  nodes_.reserve(read.size());
  for (size_t at = 0; at < order.size(); ++at) {
    const ReadNode& source = read[order[at]];
    Node node{source.radius, 0, 0, source.children.empty()};
    if (node.leaf) {
      node.first = static_cast<uint32_t>(leaf_ids_.size());
      node.count = static_cast<uint32_t>(source.rows.size());
      largest_leaf_ = std::max(largest_leaf_, source.rows.size());
      for (const size_t row : source.rows) {
        leaf_ids_.push_back(static_cast<uint32_t>(row));
        leaf_rows_.insert(leaf_rows_.end(), data + row * dimension, data + (row + 1) * dimension);
      }
    } else {
      node.first = static_cast<uint32_t>(order.size());
      node.count = static_cast<uint32_t>(source.children.size());
      order.insert(order.end(), source.children.begin(), source.children.end());
    }
    nodes_.push_back(node);
    variances_.push_back(source.variance);
  }
  centres_.resize(order.size() * dimension);
  for (size_t i = 0; i < order.size(); ++i) {
    std::memcpy(centres_.data() + i * dimension,
                recorder.bytes().data() + read[order[i]].centre_offset, dimension * sizeof(float));
  }
  return true;
}

bool KMeansTree::HoldsRows(const uint8_t* data, size_t rows, size_t dimension) const {
  if (rows != rows_ || dimension != dimension_) return false;
  for (size_t at = 0; at < leaf_ids_.size(); ++at) {
    if (std::memcmp(leaf_rows_.data() + at * dimension,
                    data + static_cast<size_t>(leaf_ids_[at]) * dimension, dimension) != 0) {
      return false;
    }
  }
  return true;
}

template <typename Queue>
bool KMeansTree::Descend(uint32_t node, float centre_distance, const uint8_t* query, int max_checks,
                         int* checks, internal::NearestTwo* result, Queue* queue,
                         SearchScratch* scratch) const {
  for (;;) {
    const Node& current = nodes_[node];
    {
      // FLANN's test for a cluster too far away, in its float operations.
      const float bsq = centre_distance;
      const float rsq = current.radius;
      const float wsq = result->Worst();
      const float val = bsq - rsq - wsq;
      const float val2 = val * val - 4 * rsq * wsq;
      if ((val > 0) && (val2 > 0)) return true;
    }
    if (current.leaf) {
      if (*checks >= max_checks && result->Full()) return true;
      int32_t* const row_distances = scratch->row_distances.data();
      flann_l2::L2BytesToRows(query,
                              leaf_rows_.data() + static_cast<size_t>(current.first) * dimension_,
                              current.count, dimension_, row_distances);
      for (uint32_t i = 0; i < current.count; ++i) {
        result->Add(static_cast<float>(row_distances[i]), leaf_ids_[current.first + i]);
      }
      *checks += static_cast<int>(current.count);
      return true;
    }
    float* const distances = scratch->distances.data();
    float* const ranks = scratch->ranks.data();
    flann_l2::L2ToCentres(query, scratch->query.data(), Centre(current.first), current.count,
                          dimension_, distances);
    uint32_t best = 0;
    for (uint32_t i = 1; i < current.count; ++i) {
      if (distances[i] < distances[best]) best = i;
    }
    const float* const variances = variances_.data() + current.first;
    for (uint32_t i = 0; i < current.count; ++i) {
      ranks[i] = distances[i] - cb_index_ * variances[i];
    }
    if (!queue->AddChildren(current.first, current.count, best, ranks, distances)) return false;
    node = current.first + best;
    centre_distance = distances[best];
  }
}

template <typename Queue>
bool KMeansTree::SearchWith(Queue* queue, const uint8_t* query, int max_checks,
                            internal::NearestTwo* result, SearchScratch* scratch) const {
  int checks = 0;
  if (!Descend(0, flann_l2::L2ToCentre(query, Centre(0), dimension_), query, max_checks, &checks,
               result, queue, scratch)) {
    return false;
  }
  uint32_t node = 0;
  float centre_distance = 0.0f;
  for (;;) {
    const PopResult popped = queue->Pop(&node, &centre_distance);
    // FLANN takes a branch, then stops if it has checked enough: which branch it took then
    // does not matter, tied or not.
    if (popped == PopResult::kEmpty || !(checks < max_checks || !result->Full())) return true;
    if (popped == PopResult::kTie) return false;
    if (!Descend(node, centre_distance, query, max_checks, &checks, result, queue, scratch)) {
      return false;
    }
  }
}

size_t KMeansTree::Search(const uint8_t* query, size_t k, int max_checks, SearchScratch* scratch,
                          int* indices, float* distances) const {
  k = std::min<size_t>(std::max<size_t>(k, 1), 2);
  scratch->query.assign(query, query + dimension_);
  scratch->distances.resize(branching_);
  scratch->ranks.resize(branching_);
  scratch->row_distances.resize(largest_leaf_);
  ++scratch->searches;
  internal::NearestTwo result(k);
  scratch->blocks.Reset(branching_, rows_);
  if (!SearchWith(&scratch->blocks, query, max_checks, &result, scratch)) {
    ++scratch->searches_again;
    result = internal::NearestTwo(k);
    scratch->flann.Reset(nodes_.size(), rows_);
    SearchWith(&scratch->flann, query, max_checks, &result, scratch);
  }
  for (size_t i = 0; i < k; ++i) {
    const bool found = i < result.Count();
    indices[i] = found ? static_cast<int>(result.Index(i)) : -1;
    distances[i] = found ? result.Distance(i) : std::numeric_limits<float>::max();
  }
  return result.Count();
}

}  // namespace tessera::flann_kmeans
