#include "distributed/shard_plan.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <stdexcept>
#include <utility>

#include "tessera/errors.h"

namespace tessera {
namespace {

// A whole non-negative decimal number, or -1.
long long ParseCount(const std::string& text) {
  if (text.empty() || text.size() > 9) return -1;
  for (const char c : text) {
    if (c < '0' || c > '9') return -1;
  }
  return std::stoll(text);
}

// The position of cell (x, y) along the Hilbert curve that fills a side x side grid
// (side a power of two); cells close on the curve are close in the grid.
uint64_t HilbertPosition(uint64_t side, uint64_t x, uint64_t y) {
  uint64_t position = 0;
  for (uint64_t half = side / 2; half > 0; half /= 2) {
    const uint64_t in_right = (x & half) != 0 ? 1 : 0;
    const uint64_t in_top = (y & half) != 0 ? 1 : 0;
    position += half * half * ((3 * in_right) ^ in_top);
    if (in_top == 0) {  // rotate the quadrant so that the curve runs on inside it
      if (in_right == 1) {
        x = side - 1 - x;
        y = side - 1 - y;
      }
      std::swap(x, y);
    }
  }
  return position;
}

}  // namespace

Shard ParseShard(const std::string& text) {
  const std::string::size_type slash = text.find('/');
  const long long index = slash == std::string::npos ? -1 : ParseCount(text.substr(0, slash));
  const long long count = slash == std::string::npos ? -1 : ParseCount(text.substr(slash + 1));
  if (index < 0 || count < 0) {
    throw InputError("--shard '" + text + "': expected K/N, shard K (from 0) of N shards");
  }
  if (count < 1) throw InputError("--shard '" + text + "': N must be at least 1");
  if (index >= count) {
    throw InputError("--shard '" + text + "': K must be in 0.." + std::to_string(count - 1));
  }
  return {static_cast<int>(index), static_cast<int>(count)};
}

std::string ShardName(const Shard& shard) {
  return std::to_string(shard.index) + "/" + std::to_string(shard.count);
}

bool ImageInShard(size_t image_index, const Shard& shard) {
  return image_index % static_cast<size_t>(shard.count) == static_cast<size_t>(shard.index);
}

double PairCost(size_t num_features1, size_t num_features2) {
  return std::max(1.0,
                  static_cast<double>(num_features1) + static_cast<double>(num_features2) / 8.0);
}

double ImageCost(size_t num_features) { return static_cast<double>(num_features) / 4.0; }

std::vector<int> AssignPairsToShards(const std::vector<std::pair<size_t, size_t>>& pairs,
                                     const std::vector<double>& pair_costs,
                                     const std::vector<double>& image_costs, int num_shards) {
  if (num_shards < 1) throw std::invalid_argument("AssignPairsToShards: no shards");
  if (pairs.size() != pair_costs.size()) {
    throw std::invalid_argument("AssignPairsToShards: " + std::to_string(pairs.size()) +
                                " pairs and " + std::to_string(pair_costs.size()) + " costs");
  }
  const size_t num_images = image_costs.size();
  uint64_t side = 1;
  while (side < num_images) side *= 2;
  std::vector<uint64_t> position(pairs.size());
  for (size_t p = 0; p < pairs.size(); ++p) {
    const auto [i, j] = pairs[p];
    if (i >= num_images || j >= num_images) {
      throw std::invalid_argument("AssignPairsToShards: pair of image " +
                                  std::to_string(std::max(i, j)) + " of " +
                                  std::to_string(num_images));
    }
    position[p] = HilbertPosition(side, std::min(i, j), std::max(i, j));
  }
  std::vector<size_t> order(pairs.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return position[a] < position[b]; });

  // Cuts the curve greedily into runs of cost at most `limit` (a run takes at least one
  // pair); returns the number of runs, and each pair's run in `run_of` when given.
  std::vector<size_t> seen_in_run(num_images, 0);  // run + 1 that last involved the image
  const auto cut = [&](double limit, std::vector<int>* run_of) {
    std::fill(seen_in_run.begin(), seen_in_run.end(), 0);
    size_t run = 0;
    double load = 0.0;
    bool empty = true;
    for (const size_t p : order) {
      const auto [i, j] = pairs[p];
      const auto added = [&](size_t r) {
        double cost = pair_costs[p];
        if (seen_in_run[i] != r + 1) cost += image_costs[i];
        if (seen_in_run[j] != r + 1 && j != i) cost += image_costs[j];
        return cost;
      };
      if (!empty && load + added(run) > limit) {
        ++run;
        load = 0.0;
      }
      load += added(run);
      seen_in_run[i] = seen_in_run[j] = run + 1;
      empty = false;
      if (run_of != nullptr) (*run_of)[p] = static_cast<int>(run);
    }
    return empty ? size_t{0} : run + 1;
  };

  // The smallest limit that needs at most num_blocks runs, by bisection between a bound
  // that needs one run (everything) and one that no run can go below (the mean).
  const size_t num_blocks = static_cast<size_t>(num_shards) * kBlocksPerShard;
  double high = std::accumulate(pair_costs.begin(), pair_costs.end(), 0.0) +
                std::accumulate(image_costs.begin(), image_costs.end(), 0.0);
  double low = high / static_cast<double>(num_blocks);
  std::vector<int> block_of(pairs.size(), 0);
  if (pairs.empty()) return block_of;
  for (int step = 0; step < 60 && high - low > 1e-9 * high; ++step) {
    const double middle = 0.5 * (low + high);
    if (cut(middle, nullptr) <= num_blocks) {
      high = middle;
    } else {
      low = middle;
    }
  }
  cut(high, &block_of);
  // Block b to shard b mod N going forth in even rounds and back in odd ones, so that no
  // shard always gets the first (or last) block of a round.
  std::vector<int> shard_of(pairs.size(), 0);
  for (size_t p = 0; p < pairs.size(); ++p) {
    const int round = block_of[p] / num_shards;
    const int place = block_of[p] % num_shards;
    shard_of[p] = round % 2 == 0 ? place : num_shards - 1 - place;
  }
  return shard_of;
}

}  // namespace tessera
