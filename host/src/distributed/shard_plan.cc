#include "distributed/shard_plan.h"

#include <algorithm>
#include <numeric>
#include <queue>
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
  return std::max(1.0, static_cast<double>(num_features1) * static_cast<double>(num_features2));
}

std::vector<int> AssignPairsToShards(const std::vector<double>& costs, int num_shards) {
  if (num_shards < 1) throw std::invalid_argument("AssignPairsToShards: no shards");
  std::vector<size_t> order(costs.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return costs[a] > costs[b]; });
  // (load, shard): the least loaded shard on top, the lowest index among equals.
  using Load = std::pair<double, int>;
  std::priority_queue<Load, std::vector<Load>, std::greater<Load>> loads;
  for (int k = 0; k < num_shards; ++k) loads.emplace(0.0, k);
  std::vector<int> shard_of(costs.size(), 0);
  for (const size_t pair : order) {
    auto [load, shard] = loads.top();
    loads.pop();
    shard_of[pair] = shard;
    loads.emplace(load + costs[pair], shard);
  }
  return shard_of;
}

}  // namespace tessera
