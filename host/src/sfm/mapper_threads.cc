#include "sfm/mapper_threads.h"

#include <algorithm>

namespace tessera {
namespace {

// Per thread: a mapper runs on one thread, and a second pipeline in the same process
// (the GUI, the Python module) keeps its own count.
thread_local int g_mapper_threads = 1;

}  // namespace

int MapperThreads() { return g_mapper_threads; }

ScopedMapperThreads::ScopedMapperThreads(int num_threads) : previous_(g_mapper_threads) {
  g_mapper_threads = std::max(1, num_threads);
}

ScopedMapperThreads::~ScopedMapperThreads() { g_mapper_threads = previous_; }

}  // namespace tessera
