// Approximate nearest neighbours with FLANN, filtered by Lowe's ratio test, an optional
// absolute distance threshold and a mutual-best (cross) check, like brute_force.
//
// Determinism: the FLANN packaged by Debian 12 (1.9.2) shuffles with std::random_device
// when it builds kd-trees (KDTreeIndex) and LSH tables, so no seed can make those
// repeatable. The default indexes are therefore FLANN's two clustering trees, whose only
// randomness is std::rand(): a hierarchical k-means tree for l2 descriptors and a
// hierarchical clustering tree for binary ones (Muja and Lowe, 2012). They are built
// after srand(random_seed) under a process-wide mutex, so the same descriptors give the
// same matches on every run and in every thread. kd-trees and LSH stay available
// (l2_index = "kdtree", hamming_index = "lsh") for speed, without that guarantee.

#include <algorithm>
#include <cmath>
#include <cstring>
#include <flann/flann.hpp>
#include <functional>
#include <future>
#include <list>
#include <memory>
#include <mutex>
#include <string>

#include "index_cache.h"
#include "index_files.h"
#include "kmeans_tree.h"
#include "tessera/match_filter.h"
#include "tessera/sdk.h"
#include "vectorized_l2.h"

namespace tessera {

struct FlannMatchOptions {
  // Ratio test, distance threshold and cross check (against the approximate nearest
  // neighbour), as every matcher reads them.
  MatchFilterOptions filter;
  // Index for l2 descriptors: "kmeans" (deterministic) or "kdtree" (randomized kd-trees).
  std::string l2_index = "kmeans";
  // Index for binary descriptors: "hierarchical" (deterministic) or "lsh".
  std::string hamming_index = "hierarchical";
  // Leaves (descriptors) examined per query by kmeans, kdtree and hierarchical: more is
  // slower and closer to exact.
  int checks = 128;
  // Children per node of the kmeans and hierarchical trees.
  int branching = 32;
  // Lloyd iterations per node of the kmeans tree.
  int kmeans_iterations = 5;
  // Number of trees of kdtree and hierarchical, searched together.
  int trees = 4;
  // Most descriptors in a leaf of the hierarchical tree.
  int leaf_max_size = 100;
  // LSH: number of hash tables, bits per key, and how far (in key bits) neighbouring
  // buckets are probed.
  int lsh_tables = 6;
  int lsh_key_size = 12;
  int lsh_multi_probe_level = 1;
  // Seed of std::rand() while kmeans and hierarchical indexes are built.
  int random_seed = 1;
  // Deterministic (kmeans, hierarchical) indexes kept for reuse: an image takes part in
  // many pairs, and its index is built once instead of once per pair. At most this many
  // indexes (0 disables the cache) ...
  int index_cache_size = 100000;
  // ... holding at most this many MiB of descriptors and trees together, least recently
  // used dropped first (the newest always stays). A build costs about as much as a
  // pair's searches, so a cache that holds every image of a large set pays for its memory
  // (descriptors alone: 256 KB for 2,000 SIFT features, 1.5 MB for 12,000).
  int index_cache_mb = 1024;
};

// The options, listed once: read, checked and described (`tessera plugins flann`) from here.
template <typename Visit>
void VisitFlannMatchOptions(FlannMatchOptions& o, const Visit& visit) {
  VisitMatchFilterOptions(o.filter, visit);
  visit("l2_index", o.l2_index, option_list::Choices{"kmeans", "kdtree"},
        "index for l2 descriptors: kmeans (deterministic) or kdtree (not repeatable)");
  visit("hamming_index", o.hamming_index, option_list::Choices{"hierarchical", "lsh"},
        "index for binary descriptors: hierarchical (deterministic) or lsh (not repeatable)");
  visit("checks", o.checks, 1, 100000000,
        "descriptors examined per query by kmeans, kdtree and hierarchical; more is slower and "
        "closer to exact");
  visit("branching", o.branching, 2, 1024,
        "children per node of the kmeans and hierarchical trees");
  visit("kmeans_iterations", o.kmeans_iterations, 1, 100,
        "Lloyd iterations per node of the kmeans tree");
  visit("trees", o.trees, 1, 64, "number of kdtree / hierarchical trees searched together");
  visit("leaf_max_size", o.leaf_max_size, 1, 100000,
        "most descriptors in a leaf of the hierarchical trees");
  visit("lsh_tables", o.lsh_tables, 1, 64, "LSH hash tables");
  visit("lsh_key_size", o.lsh_key_size, 1, 32, "LSH key bits, at most the descriptor's bits");
  visit("lsh_multi_probe_level", o.lsh_multi_probe_level, 0, 4,
        "LSH: also probe buckets whose keys differ in this many bits");
  visit("random_seed", o.random_seed, 0, std::numeric_limits<int>::max(),
        "seed of std::rand() for kmeans and hierarchical builds");
  visit("index_cache_size", o.index_cache_size, 0, 1000000,
        "most deterministic indexes kept for reuse across pairs; 0: off");
  visit("index_cache_mb", o.index_cache_mb, 1, 1000000,
        "most MiB those indexes hold, descriptors and trees together");
}

namespace {

// std::rand() is process-wide: builds that must replay one seeded sequence take turns.
std::mutex& SeededBuildMutex() {
  static std::mutex mutex;
  return mutex;
}

flann::Matrix<unsigned char> WrapDescriptors(const FeatureDescriptors& descriptors) {
  // FLANN wants a mutable pointer but only reads through it.
  return flann::Matrix<unsigned char>(const_cast<uint8_t*>(descriptors.data.data()),
                                      static_cast<size_t>(descriptors.size()),
                                      static_cast<size_t>(descriptors.dimension()));
}

// The concrete index type is used (not NNIndex) because LshIndex hides knnSearch with a
// version that keeps a descriptor found in several tables from filling both slots.
template <typename Index>
NearestNeighbors Search(const Index& index, const FeatureDescriptors& query, size_t k,
                        const flann::SearchParams& params, bool squared_distances) {
  std::vector<std::vector<size_t>> indices;
  std::vector<std::vector<typename Index::DistanceType>> distances;
  index.knnSearch(WrapDescriptors(query), indices, distances, k, params);
  const size_t num_queries = static_cast<size_t>(query.size());
  NearestNeighbors neighbors(num_queries);
  const auto to_distance = [squared_distances](double value) {
    return static_cast<float>(squared_distances ? std::sqrt(value) : value);
  };
  for (size_t i = 0; i < num_queries && i < indices.size(); ++i) {
    if (!indices[i].empty()) {
      neighbors.best[i] = static_cast<int>(indices[i][0]);
      neighbors.best_distance[i] = to_distance(distances[i][0]);
    }
    if (indices[i].size() > 1) {
      neighbors.second[i] = static_cast<int>(indices[i][1]);
      neighbors.second_distance[i] = to_distance(distances[i][1]);
    }
  }
  return neighbors;
}

using flann_cache::HierarchicalHammingIndex;
using flann_cache::IndexCache;
using flann_cache::KMeansL2Index;

// The same neighbours as Search over the FLANN index the tree was copied from.
NearestNeighbors Search(const flann_kmeans::KMeansTree& tree, const FeatureDescriptors& query,
                        size_t k, int checks) {
  const size_t num_queries = static_cast<size_t>(query.size());
  const size_t dimension = static_cast<size_t>(query.dimension());
  NearestNeighbors neighbors(num_queries);
  flann_kmeans::SearchScratch scratch;
  int indices[2];
  float distances[2];
  for (size_t i = 0; i < num_queries; ++i) {
    const size_t found =
        tree.Search(query.data.data() + i * dimension, k, checks, &scratch, indices, distances);
    if (found > 0) {
      neighbors.best[i] = indices[0];
      neighbors.best_distance[i] = std::sqrt(distances[0]);
    }
    if (found > 1 && k > 1) {
      neighbors.second[i] = indices[1];
      neighbors.second_distance[i] = std::sqrt(distances[1]);
    }
  }
  return neighbors;
}

}  // namespace

class FlannMatcher : public Matcher {
 public:
  explicit FlannMatcher(const nlohmann::json& options) {
    OptionReader reader(options);
    VisitFlannMatchOptions(options_, option_list::Reader(&reader));
    reader.Finish();
    const size_t cache_bytes = static_cast<size_t>(options_.index_cache_mb) << 20;
    const auto warn = [this](const std::string& text) { log().Warn(text); };
    kmeans_cache_ =
        std::make_unique<IndexCache<KMeansL2Index>>(options_.index_cache_size, cache_bytes, warn);
    hierarchical_cache_ = std::make_unique<IndexCache<HierarchicalHammingIndex>>(
        options_.index_cache_size, cache_bytes, warn);
    effective_options_ = reader.Effective();
  }

  FeatureMatches Match(const FeatureDescriptors& descriptors1,
                       const FeatureDescriptors& descriptors2) const override {
    // An image without features has nothing to match, whatever its declared metric.
    if (descriptors1.size() == 0 || descriptors2.size() == 0) return {};
    CheckCompatible(descriptors1, descriptors2);
    // Forward: the two nearest rows of set 2 for each row of set 1. Backward (cross
    // check): the nearest row of set 1 for each row of set 2.
    const NearestNeighbors forward = FindNeighbors(descriptors2, descriptors1, 2);
    NearestNeighbors backward;
    if (options_.filter.cross_check) {
      backward = FindBackwardNeighbors(forward, descriptors1, descriptors2);
    }
    return FilterMatches(options_.filter, forward, backward, descriptors2.size());
  }

  // The deterministic indexes (kmeans, hierarchical) are kept in `folder`: kdtree and lsh
  // are random, so a file of theirs would not give the matches of a fresh build.
  void SetCacheFolder(const std::filesystem::path& folder) override {
    const std::string flann = std::string("flann ") + FLANN_VERSION_ + " format 1 seed " +
                              std::to_string(options_.random_seed) + " branching " +
                              std::to_string(options_.branching);
    kmeans_files_ = flann_index_files::IndexFiles(
        folder, flann + " kmeans kmeanspp iterations " +
                    std::to_string(options_.kmeans_iterations) + " distance vectorized_l2");
    hierarchical_files_ = flann_index_files::IndexFiles(
        folder, flann + " hierarchical kmeanspp trees " + std::to_string(options_.trees) +
                    " leaf_max_size " + std::to_string(options_.leaf_max_size));
  }

  // Builds and writes the index that Match searches for these descriptors, unless its file
  // is there already. Both directions of a pair search such an index (the cross check
  // searches image 1's), so every image needs one.
  void Prepare(const FeatureDescriptors& descriptors) const override {
    if (descriptors.size() == 0) return;
    const flann_index_files::DescriptorsKey key = flann_index_files::KeyOf(descriptors);
    if (descriptors.metric == DescriptorMetric::kL2 && options_.l2_index == "kmeans" &&
        kmeans_files_.enabled() && !kmeans_files_.Exists(key)) {
      kmeans_files_.Save(key, *Build<KMeansL2Index>(descriptors, KMeansParams(), true));
    } else if (descriptors.metric == DescriptorMetric::kHamming &&
               options_.hamming_index == "hierarchical" && hierarchical_files_.enabled() &&
               !hierarchical_files_.Exists(key)) {
      hierarchical_files_.Save(
          key, *Build<HierarchicalHammingIndex>(descriptors, HierarchicalParams(), true));
    }
  }

 private:
  flann::KMeansIndexParams KMeansParams() const {
    return flann::KMeansIndexParams(options_.branching, options_.kmeans_iterations,
                                    flann::FLANN_CENTERS_KMEANSPP);
  }

  flann::HierarchicalClusteringIndexParams HierarchicalParams() const {
    return flann::HierarchicalClusteringIndexParams(
        options_.branching, flann::FLANN_CENTERS_KMEANSPP, options_.trees, options_.leaf_max_size);
  }

  // The index of `data` from its file in `files` when there is a whole one; otherwise
  // built, and written there (a file that cannot be written only costs a later build).
  template <typename Index>
  std::unique_ptr<Index> LoadOrBuild(const FeatureDescriptors& data,
                                     const flann_index_files::DescriptorsKey& key,
                                     const flann::IndexParams& params,
                                     const flann_index_files::IndexFiles* files) const {
    if (files != nullptr && files->enabled()) {
      auto index = std::make_unique<Index>(WrapDescriptors(data), params);
      if (files->Load(key, index.get()) && index->size() == static_cast<size_t>(data.size()) &&
          index->veclen() == static_cast<size_t>(data.dimension())) {
        return index;
      }
    }
    auto index = Build<Index>(data, params, /*seeded=*/true);
    if (files != nullptr && files->enabled()) {
      try {
        files->Save(key, *index);
      } catch (const std::exception&) {
      }
    }
    return index;
  }

  void CheckCompatible(const FeatureDescriptors& descriptors1,
                       const FeatureDescriptors& descriptors2) const {
    CheckDescriptorsMatchable(descriptors1, descriptors2);
    if (descriptors1.metric == DescriptorMetric::kHamming && options_.hamming_index == "lsh" &&
        options_.lsh_key_size > 8 * descriptors1.dimension()) {
      throw InputError("The flann matcher's lsh_key_size of " +
                       std::to_string(options_.lsh_key_size) + " bits exceeds the " +
                       std::to_string(8 * descriptors1.dimension()) +
                       " bits of the binary descriptors.");
    }
  }

  // Builds an index over `data`; seeded builds replay one std::rand() sequence.
  template <typename Index>
  std::unique_ptr<Index> Build(const FeatureDescriptors& data, const flann::IndexParams& params,
                               bool seeded) const {
    auto index = std::make_unique<Index>(WrapDescriptors(data), params);
    if (seeded) {
      std::lock_guard<std::mutex> lock(SeededBuildMutex());
      flann::seed_random(static_cast<unsigned int>(options_.random_seed));
      index->buildIndex();
    } else {
      index->buildIndex();
    }
    return index;
  }

  NearestNeighbors FindNeighbors(const FeatureDescriptors& data, const FeatureDescriptors& query,
                                 size_t k) const {
    k = std::min(k, static_cast<size_t>(data.size()));
    flann::SearchParams search_params(options_.checks);
    search_params.cores = 1;  // the host parallelises over pairs
    if (data.metric == DescriptorMetric::kL2) {
      using Distance = flann::L2<unsigned char>;
      if (options_.l2_index == "kmeans") {
        const auto build = [this](const FeatureDescriptors& descriptors,
                                  const flann_index_files::DescriptorsKey& key, bool shared) {
          return LoadOrBuild<KMeansL2Index>(descriptors, key, KMeansParams(),
                                            shared ? &kmeans_files_ : nullptr);
        };
        if (options_.index_cache_size > 0) {
          const auto entry = kmeans_cache_->Get(data, build);
          if (entry->tree) return Search(*entry->tree, query, k, options_.checks);
          return Search(*entry->index, query, k, search_params, /*squared_distances=*/true);
        }
        return Search(*build(data, flann_index_files::KeyOf(data), /*shared=*/true), query, k,
                      search_params, /*squared_distances=*/true);
      }
      const auto index = Build<flann::KDTreeIndex<Distance>>(
          data, flann::KDTreeIndexParams(options_.trees), /*seeded=*/false);
      return Search(*index, query, k, search_params, /*squared_distances=*/true);
    }
    using Distance = flann::Hamming<unsigned char>;
    if (options_.hamming_index == "hierarchical") {
      const auto build = [this](const FeatureDescriptors& descriptors,
                                const flann_index_files::DescriptorsKey& key, bool shared) {
        return LoadOrBuild<HierarchicalHammingIndex>(descriptors, key, HierarchicalParams(),
                                                     shared ? &hierarchical_files_ : nullptr);
      };
      if (options_.index_cache_size > 0) {
        const auto entry = hierarchical_cache_->Get(data, build);
        return Search(*entry->index, query, k, search_params, /*squared_distances=*/false);
      }
      return Search(*build(data, flann_index_files::KeyOf(data), /*shared=*/true), query, k,
                    search_params, /*squared_distances=*/false);
    }
    const auto index = Build<flann::LshIndex<Distance>>(
        data,
        flann::LshIndexParams(options_.lsh_tables, options_.lsh_key_size,
                              options_.lsh_multi_probe_level),
        /*seeded=*/false);
    return Search(*index, query, k, search_params, /*squared_distances=*/false);
  }

  // The nearest row of set 1 for each row of set 2 that some row of set 1 would be
  // matched to; -1 for the others, which the cross check can never accept. Searching
  // only those (typically a third of set 2) gives the same matches as searching all:
  // each query's neighbours do not depend on the other queries.
  NearestNeighbors FindBackwardNeighbors(const NearestNeighbors& forward,
                                         const FeatureDescriptors& descriptors1,
                                         const FeatureDescriptors& descriptors2) const {
    std::vector<int> candidates;
    std::vector<char> is_candidate(static_cast<size_t>(descriptors2.size()), 0);
    for (size_t i = 0; i < forward.best.size(); ++i) {
      const int j = forward.best[i];
      if (j >= 0 && PassesRatioAndDistance(options_.filter, forward, i, descriptors2.size()) &&
          !is_candidate[j]) {
        is_candidate[j] = 1;
        candidates.push_back(j);
      }
    }
    std::sort(candidates.begin(), candidates.end());
    NearestNeighbors backward;
    backward.best.assign(static_cast<size_t>(descriptors2.size()), -1);
    if (candidates.empty()) return backward;
    FeatureDescriptors queries;
    queries.metric = descriptors2.metric;
    queries.data.resize(static_cast<Eigen::Index>(candidates.size()), descriptors2.dimension());
    for (size_t row = 0; row < candidates.size(); ++row) {
      queries.data.row(static_cast<Eigen::Index>(row)) = descriptors2.data.row(candidates[row]);
    }
    const NearestNeighbors found = FindNeighbors(descriptors1, queries, 1);
    for (size_t row = 0; row < candidates.size(); ++row) {
      backward.best[static_cast<size_t>(candidates[row])] = found.best[row];
    }
    return backward;
  }

  FlannMatchOptions options_;
  std::unique_ptr<IndexCache<KMeansL2Index>> kmeans_cache_;
  std::unique_ptr<IndexCache<HierarchicalHammingIndex>> hierarchical_cache_;
  flann_index_files::IndexFiles kmeans_files_;  // none until SetCacheFolder
  flann_index_files::IndexFiles hierarchical_files_;
};

}  // namespace tessera

TESSERA_PLUGIN_OPTIONS(tessera::FlannMatchOptions, tessera::VisitFlannMatchOptions)
TESSERA_PLUGIN(matcher, tessera::FlannMatcher, "flann", "1.0.0",
               "Approximate nearest neighbours (FLANN k-means / hierarchical clustering trees) "
               "with ratio test and cross check")
