#pragma once

#include <cstdint>
#include <random>

namespace tessera {

// A seed for one task (e.g. one image pair) derived from the run's seed, so results
// do not depend on which thread runs the task or in which order.
inline uint64_t DeriveSeed(uint64_t run_seed, uint64_t task_id) {
  // SplitMix64 finalizer over the combination.
  uint64_t z = run_seed + 0x9E3779B97F4A7C15ull * (task_id + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

using RandomEngine = std::mt19937_64;

}  // namespace tessera
