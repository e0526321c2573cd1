#pragma once

// The flann matcher's cache of indexes: each image's index is built once and shared by
// every pair that searches it (see IndexCache below).

#include <algorithm>
#include <cstring>
#include <flann/flann.hpp>
#include <functional>
#include <future>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <type_traits>

#include "index_files.h"
#include "kmeans_tree.h"
#include "tessera/features.h"
#include "vectorized_l2.h"

namespace tessera::flann_cache {

using VectorizedL2Uint8 = flann_l2::VectorizedL2Uint8;
using KMeansL2Index = flann::KMeansIndex<VectorizedL2Uint8>;
using HierarchicalHammingIndex = flann::HierarchicalClusteringIndex<flann::Hamming<unsigned char>>;

// Indexes of one type built over their own copy of the descriptors (FLANN keeps a
// pointer to the data), shared by every pair that searches the same image, least
// recently used evicted first once there are more than `capacity` of them or they hold
// more than `max_bytes` (descriptors plus the index's own memory; the newest always
// stays). Thread-safe; a second caller of an index being built waits for it instead of
// building it again, and an evicted index lives on while a pair still searches it.
template <typename Index>
class IndexCache {
 public:
  // A k-means index is copied into a flat tree (the same neighbours, found faster, and a
  // copy of the rows of its own), and then dropped with the descriptors it was built
  // over; an index whose tree cannot be read is kept and searched.
  struct Entry {
    FeatureDescriptors descriptors;  // empty once `tree` holds the rows
    std::unique_ptr<Index> index;
    std::unique_ptr<const flann_kmeans::KMeansTree> tree;
    size_t Bytes() const {
      return static_cast<size_t>(descriptors.data.size()) +
             (index ? static_cast<size_t>(std::max(0, index->usedMemory())) : 0) +
             (tree ? tree->Bytes() : 0);
    }
    // Whether the index is over exactly these descriptors (hashes can collide).
    bool Holds(const FeatureDescriptors& other) const {
      if (descriptors.metric != other.metric) return false;
      if (tree) {
        return tree->HoldsRows(other.data.data(), static_cast<size_t>(other.size()),
                               static_cast<size_t>(other.dimension()));
      }
      return descriptors.data.rows() == other.data.rows() &&
             descriptors.data.cols() == other.data.cols() &&
             std::memcmp(descriptors.data.data(), other.data.data(),
                         static_cast<size_t>(other.data.size())) == 0;
    }
  };
  // Builds (or loads) the index of descriptors with this key; `shared` false: for this
  // caller alone, without the index files.
  using Builder = std::function<std::unique_ptr<Index>(
      const FeatureDescriptors&, const flann_index_files::DescriptorsKey&, bool shared)>;

  // `warn` receives the one line said when an index cannot be copied into a flat tree.
  IndexCache(size_t capacity, size_t max_bytes, std::function<void(const std::string&)> warn)
      : capacity_(capacity), max_bytes_(max_bytes), warn_(std::move(warn)) {}

  std::shared_ptr<const Entry> Get(const FeatureDescriptors& descriptors, const Builder& build) {
    const flann_index_files::DescriptorsKey key = flann_index_files::KeyOf(descriptors);
    std::shared_future<std::shared_ptr<const Entry>> future;
    std::promise<std::shared_ptr<const Entry>> promise;
    bool must_build = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      for (auto it = entries_.begin(); it != entries_.end(); ++it) {
        if (it->key == key) {
          entries_.splice(entries_.begin(), entries_, it);  // most recently used first
          future = it->future;
          break;
        }
      }
      if (!future.valid()) {
        future = promise.get_future().share();
        entries_.push_front({key, future, 0});
        Evict();
        must_build = true;
      }
    }
    if (must_build) {
      try {
        auto entry = std::make_shared<Entry>();
        entry->descriptors = descriptors;
        entry->index = build(entry->descriptors, key, /*shared=*/true);
        Flatten(entry.get());
        const size_t bytes = entry->Bytes();
        promise.set_value(std::move(entry));
        std::lock_guard<std::mutex> lock(mutex_);
        for (Slot& slot : entries_) {
          if (slot.key == key && slot.bytes == 0) {
            slot.bytes = bytes;
            bytes_ += bytes;
            break;
          }
        }
        Evict();
      } catch (...) {
        promise.set_exception(std::current_exception());
        Forget(key);
        throw;
      }
    }
    std::shared_ptr<const Entry> entry = future.get();
    // A hash collision between different descriptors: build privately.
    if (!entry->Holds(descriptors)) {
      auto own = std::make_shared<Entry>();
      own->descriptors = descriptors;
      own->index = build(own->descriptors, key, /*shared=*/false);
      Flatten(own.get());
      return own;
    }
    return entry;
  }

 private:
  struct Slot {
    flann_index_files::DescriptorsKey key;
    std::shared_future<std::shared_ptr<const Entry>> future;
    size_t bytes;  // 0 while it is being built
  };

  // Under mutex_: drops least recently used entries beyond either limit, never the newest.
  void Evict() {
    while (entries_.size() > 1 && (entries_.size() > capacity_ || bytes_ > max_bytes_)) {
      bytes_ -= entries_.back().bytes;
      entries_.pop_back();
    }
  }

  void Flatten(Entry* entry) {
    if constexpr (std::is_same_v<Index, KMeansL2Index>) {
      entry->tree =
          flann_kmeans::KMeansTree::FromIndex(*entry->index, entry->descriptors.data.data(),
                                              static_cast<size_t>(entry->descriptors.size()),
                                              static_cast<size_t>(entry->descriptors.dimension()));
      if (entry->tree) {
        entry->index.reset();
        entry->descriptors.data.resize(0, entry->descriptors.data.cols());
      } else if (warn_) {
        // Another libflann lays its index out otherwise: the same matches, found slower.
        std::call_once(fallback_said_, [this] {
          warn_(
              "this libflann's k-means index is not laid out as the flat tree expects; "
              "FLANN's own, slower search is used (the same matches)");
        });
      }
    }
  }

  void Forget(const flann_index_files::DescriptorsKey& key) {
    std::lock_guard<std::mutex> lock(mutex_);
    entries_.remove_if([this, key](const Slot& slot) {
      if (slot.key != key) return false;
      bytes_ -= slot.bytes;
      return true;
    });
  }

  size_t capacity_;
  size_t max_bytes_;
  std::function<void(const std::string&)> warn_;
  std::once_flag fallback_said_;
  std::mutex mutex_;
  std::list<Slot> entries_;
  size_t bytes_ = 0;  // of the built entries in entries_
};

}  // namespace tessera::flann_cache
