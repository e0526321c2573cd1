#pragma once

// How many threads Tessera::sfm's building blocks may use for work asked of them on the
// calling thread (host-internal: the installed headers' signatures stay as they are).
// 1 unless a ScopedMapperThreads is alive on that thread: the map stage opens one with
// the pipeline's thread count around the mapper plugin's Map, so that the building
// blocks a mapper calls (ViewGraph::Build) use the cores it was given, and a program
// that links Tessera::sfm without the host keeps one thread, as before.

#include "tessera/sfm/export.h"

namespace tessera {

// The thread count for work asked on this thread: the innermost live scope's, else 1.
TESSERA_SFM_EXPORT int MapperThreads();

class TESSERA_SFM_EXPORT ScopedMapperThreads {
 public:
  // num_threads below 1 counts as 1.
  explicit ScopedMapperThreads(int num_threads);
  ~ScopedMapperThreads();
  ScopedMapperThreads(const ScopedMapperThreads&) = delete;
  ScopedMapperThreads& operator=(const ScopedMapperThreads&) = delete;

 private:
  int previous_;
};

}  // namespace tessera
