// What discovery costs on the bundled plugins: the whole of Discover (probe in a child,
// then load in this process, as every verb does), the child probe alone, and loading
// alone (what Discover did before the probe).
//   build/bin/plugin_discovery_benchmark [--benchmark_repetitions=5]

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdlib>

#include "plugin/plugin_probe.h"
#include "plugin/plugin_registry.h"

namespace tessera {
namespace {

std::filesystem::path BundledDir() {
  const char* dir = std::getenv("TESSERA_PLUGIN_DIR");
  return dir != nullptr ? dir : TESSERA_BENCHMARK_PLUGIN_DIR;
}

std::vector<std::filesystem::path> BundledFiles() {
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(BundledDir())) {
    if (entry.path().extension() == ".so") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

void BM_Discover(benchmark::State& state) {
  size_t num_usable = 0;
  for (auto _ : state) {
    const PluginRegistry registry = PluginRegistry::Discover({BundledDir()});
    num_usable = 0;
    for (const auto& record : registry.records()) num_usable += record.usable();
  }
  state.counters["plugins"] = static_cast<double>(num_usable);
}
BENCHMARK(BM_Discover)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ProbeInChild(benchmark::State& state) {
  const auto files = BundledFiles();
  for (auto _ : state) benchmark::DoNotOptimize(ProbePluginFiles(files));
  state.counters["plugins"] = static_cast<double>(files.size());
}
BENCHMARK(BM_ProbeInChild)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_LoadInProcess(benchmark::State& state) {
  const auto files = BundledFiles();
  for (auto _ : state) {
    std::vector<PluginRecord> records;
    for (const auto& file : files) records.push_back(InspectPluginFile(file));
    benchmark::DoNotOptimize(records);
  }
  state.counters["plugins"] = static_cast<double>(files.size());
}
BENCHMARK(BM_LoadInProcess)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace tessera
