// Partitioned mapping against one unpartitioned run, on the synthetic paths of
// mapper_benchmark (n cameras one unit apart along a line, about 500 keypoints per
// image, pairs at most 10 positions apart). Not timed: the scene, and the whole set
// mapped once for reference. Timed, one after the other on one thread: the cut
// (PartitionViewGraph on the pairs weighted by their inliers, clusters of at most 300
// sharing 40), each cluster mapped alone on its images and the pairs among them
// (RestrictMapperInput, as `map --cluster K` does), and the merge (MergeClusterModels
// along the cut's tree). Bundle adjustment by the Ceres plugin on one thread throughout.
//
// Counters: the clusters' map seconds (slowest and summed), the whole set's, the
// merge's and the cut's; the merged largest model's images and the number of models;
// the position error of the merged and the whole model against the truth, and of the
// merged model against the whole one; and the projected wall time on W workers: the
// cut, plus the makespan of the clusters' map times placed longest first onto the
// least-loaded of W workers, plus the merge. A table of every run is printed at the end.
//
//   partition_benchmark --benchmark_filter='Global/1000'
//   partition_benchmark --benchmark_filter='Incremental/1000'
//   SPDLOG_LEVEL=info partition_benchmark ...  # the mappers' and the merge's logs

#include <benchmark/benchmark.h>
#include <spdlog/cfg/env.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "eval/evaluation.h"
#include "partition/cluster_map.h"
#include "partition/cluster_merge.h"
#include "partition/view_graph_partitioner.h"
#include "synthetic_scene.h"
#include "tessera/sfm/global_mapper.h"
#include "tessera/sfm/incremental_pipeline.h"
#include "test_support.h"

namespace tessera {
namespace {

using MapFunction = std::function<std::vector<Reconstruction>(const MapperInput&)>;

testing::SyntheticScene MakePathScene(int num_images) {
  testing::SyntheticSceneOptions options;
  options.layout = testing::SyntheticSceneOptions::Layout::kPath;
  options.num_images = num_images;
  options.num_points = 40 * num_images;
  options.max_pair_gap = 10;
  return testing::MakeSyntheticScene(options);
}

std::vector<Reconstruction> MapIncremental(const MapperInput& input) {
  return IncrementalPipeline(IncrementalMapperOptions{}, testing::CeresAdjusterOnOneThread(), 0)
      .Reconstruct(input)
      .models;
}

std::vector<Reconstruction> MapGlobal(const MapperInput& input) {
  return GlobalMapper::Reconstruct(input, testing::CeresAdjusterOnOneThread(),
                                   GlobalMapperOptions{})
      .models;
}

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The longest time any of `workers` workers is busy when the jobs go, longest first,
// each to the least-loaded worker.
double Makespan(std::vector<double> seconds, size_t workers) {
  std::sort(seconds.rbegin(), seconds.rend());
  std::vector<double> load(workers, 0.0);
  for (const double job : seconds) *std::min_element(load.begin(), load.end()) += job;
  return *std::max_element(load.begin(), load.end());
}

// A model's poses as ground truth, by image name.
std::map<std::string, GroundTruthPose> PosesOf(const Reconstruction& model) {
  std::map<std::string, GroundTruthPose> poses;
  for (const auto& [image_id, image] : model.images) {
    GroundTruthPose pose;
    pose.R_cam_from_world = image.cam_from_world.rotation.toRotationMatrix();
    pose.center_in_world = image.ProjectionCenter();
    poses[image.name] = pose;
  }
  return poses;
}

// The view graph of the scene: images as nodes in id order, pairs weighted by inliers.
std::vector<WeightedEdge> ViewGraphOf(const MapperInput& input, std::map<image_t, size_t>* node_of,
                                      std::vector<std::string>* name_of) {
  for (const auto& [image_id, image] : input.images) {
    node_of->emplace(image_id, name_of->size());
    name_of->push_back(image.name);
  }
  std::vector<WeightedEdge> edges;
  for (const MapperInput::Pair& pair : input.pairs) {
    edges.push_back({node_of->at(pair.image_id1), node_of->at(pair.image_id2),
                     static_cast<double>(pair.geometry.inlier_matches.size())});
  }
  return edges;
}

struct PartitionedRun {
  size_t num_clusters = 0;
  double partition_seconds = 0;
  std::vector<double> cluster_seconds;
  double merge_seconds = 0;
  size_t num_merges_refused = 0;
  size_t num_images_lost_in_final_adjustment = 0;
  std::vector<Reconstruction> models;  // largest first
};

// Cut, each cluster mapped alone, merge: each step timed.
PartitionedRun MapPartitioned(const MapperInput& input, const MapFunction& map) {
  PartitionedRun run;
  auto start = std::chrono::steady_clock::now();
  std::map<image_t, size_t> node_of;
  std::vector<std::string> name_of;
  const std::vector<WeightedEdge> edges = ViewGraphOf(input, &node_of, &name_of);
  PartitionOptions partition_options;
  partition_options.max_nodes = 300;
  partition_options.overlap = 40;
  const ViewGraphPartition partition = PartitionViewGraph(name_of.size(), edges, partition_options);
  run.partition_seconds = SecondsSince(start);
  run.num_clusters = partition.clusters.size();

  std::map<int, std::vector<Reconstruction>> cluster_models;
  for (size_t c = 0; c < partition.clusters.size(); ++c) {
    std::vector<std::string> names;
    for (const size_t node : partition.clusters[c].nodes) names.push_back(name_of[node]);
    start = std::chrono::steady_clock::now();
    const MapperInput restricted = RestrictMapperInput(input, names);
    cluster_models[static_cast<int>(c)] = map(restricted);
    run.cluster_seconds.push_back(SecondsSince(start));
  }

  start = std::chrono::steady_clock::now();
  ClusterMergeResult merged =
      MergeClusterModels(partition.tree, std::move(cluster_models),
                         testing::CeresAdjusterOnOneThread(), ClusterMergeOptions{});
  run.merge_seconds = SecondsSince(start);
  for (const ClusterMergeRecord& record : merged.merges) {
    if (!record.merged) {
      ++run.num_merges_refused;
      spdlog::warn("merge refused: {}", record.Line());
    }
  }
  run.num_images_lost_in_final_adjustment = merged.images_lost_in_final_adjustment.size();
  for (ClusterModel& model : merged.models) run.models.push_back(std::move(model.model));
  return run;
}

// One row of the closing table.
struct Row {
  std::string name;
  std::map<std::string, double> figures;
};
std::vector<Row>& Rows() {
  static std::vector<Row> rows;
  return rows;
}

void SetCounters(const std::string& name, const testing::SyntheticScene& scene,
                 const std::vector<Reconstruction>& whole, double whole_seconds,
                 const PartitionedRun& run, benchmark::State* state) {
  auto& counters = state->counters;
  const double slowest = *std::max_element(run.cluster_seconds.begin(), run.cluster_seconds.end());
  double sum = 0;
  for (const double seconds : run.cluster_seconds) sum += seconds;
  counters["images"] = static_cast<double>(scene.input.images.size());
  counters["clusters"] = static_cast<double>(run.num_clusters);
  counters["partition_s"] = run.partition_seconds;
  counters["slowest_cluster_s"] = slowest;
  counters["sum_clusters_s"] = sum;
  counters["merge_s"] = run.merge_seconds;
  counters["whole_s"] = whole_seconds;
  for (const size_t workers : {1, 8, 32}) {
    counters["wall_" + std::to_string(workers) + "w_s"] =
        run.partition_seconds + Makespan(run.cluster_seconds, workers) + run.merge_seconds;
  }
  counters["models"] = static_cast<double>(run.models.size());
  counters["registered"] =
      run.models.empty() ? 0.0 : static_cast<double>(run.models[0].images.size());
  counters["whole_registered"] = whole.empty() ? 0.0 : static_cast<double>(whole[0].images.size());
  counters["merges_refused"] = static_cast<double>(run.num_merges_refused);
  counters["lost_final_ba"] = static_cast<double>(run.num_images_lost_in_final_adjustment);
  const auto truth = scene.GroundTruth();
  if (!run.models.empty()) {
    const EvaluationResult merged = EvaluateReconstruction(run.models[0], truth);
    counters["pos_err_mean"] = merged.position_error_mean;
    counters["pos_err_max"] = merged.position_error_max;
    counters["rot_err_max_deg"] = merged.rotation_error_max_deg;
  }
  if (!whole.empty()) {
    const EvaluationResult reference = EvaluateReconstruction(whole[0], truth);
    counters["whole_pos_err_mean"] = reference.position_error_mean;
    counters["whole_pos_err_max"] = reference.position_error_max;
    counters["whole_rot_err_max_deg"] = reference.rotation_error_max_deg;
  }
  if (!run.models.empty() && !whole.empty()) {
    // The merged model against the whole one, as if the whole one were the truth.
    const EvaluationResult against_whole = EvaluateReconstruction(run.models[0], PosesOf(whole[0]));
    counters["vs_whole_pos_err_mean"] = against_whole.position_error_mean;
    counters["vs_whole_pos_err_max"] = against_whole.position_error_max;
  }
  Row row{name, {}};
  for (const auto& [name, counter] : counters) row.figures[name] = counter.value;
  Rows().push_back(std::move(row));
}

void RunPartitioned(benchmark::State& state, const std::string& mapper, const MapFunction& map) {
  const testing::SyntheticScene scene = MakePathScene(static_cast<int>(state.range(0)));
  const auto start = std::chrono::steady_clock::now();
  const std::vector<Reconstruction> whole = map(scene.input);
  const double whole_seconds = SecondsSince(start);
  PartitionedRun run;
  for (auto _ : state) run = MapPartitioned(scene.input, map);
  SetCounters(mapper + "/" + std::to_string(state.range(0)), scene, whole, whole_seconds, run,
              &state);
}

void BM_PartitionedIncremental(benchmark::State& state) {
  RunPartitioned(state, "incremental", MapIncremental);
}
void BM_PartitionedGlobal(benchmark::State& state) { RunPartitioned(state, "global", MapGlobal); }

void PathSizes(benchmark::internal::Benchmark* benchmark) {
  for (const int num_images : {1000, 3000}) benchmark->Arg(num_images);
  benchmark->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();
}

BENCHMARK(BM_PartitionedIncremental)->Apply(PathSizes);
BENCHMARK(BM_PartitionedGlobal)->Apply(PathSizes);

void PrintTable() {
  if (Rows().empty()) return;
  std::printf("\n%-16s %8s %5s %9s %9s %9s %8s %8s %8s %8s %8s %6s %6s %9s %9s %9s %7s %7s\n",
              "run", "clusters", "cut_s", "slowest_s", "sum_s", "whole_s", "merge_s", "wall_1w",
              "wall_8w", "wall_32w", "reg/n", "models", "refused", "pos_err", "whole_pe",
              "vs_whole", "rot_max", "w_rot_mx");
  for (const Row& row : Rows()) {
    const auto figure = [&](const std::string& name) {
      const auto found = row.figures.find(name);
      return found == row.figures.end() ? -1.0 : found->second;
    };
    const std::string registered = std::to_string(static_cast<int>(figure("registered"))) + "/" +
                                   std::to_string(static_cast<int>(figure("images")));
    std::printf(
        "%-16s %8.0f %5.1f %9.1f %9.1f %9.1f %8.1f %8.1f %8.1f %8.1f %8s %6.0f %6.0f "
        "%9.4f %9.4f %9.4f %7.2f %7.2f\n",
        row.name.c_str(), figure("clusters"), figure("partition_s"), figure("slowest_cluster_s"),
        figure("sum_clusters_s"), figure("whole_s"), figure("merge_s"), figure("wall_1w_s"),
        figure("wall_8w_s"), figure("wall_32w_s"), registered.c_str(), figure("models"),
        figure("merges_refused"), figure("pos_err_mean"), figure("whole_pos_err_mean"),
        figure("vs_whole_pos_err_mean"), figure("rot_err_max_deg"),
        figure("whole_rot_err_max_deg"));
  }
  std::printf(
      "pos_err, whole_pe: mean position error against the truth (path units; the path is "
      "n - 1 long); vs_whole: merged against the whole model; rot_max, w_rot_mx: largest rotation "
      "error (deg) of the merged and the whole model\n");
}

}  // namespace
}  // namespace tessera

int main(int argc, char** argv) {
  spdlog::set_level(spdlog::level::warn);
  spdlog::cfg::load_env_levels();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  tessera::PrintTable();
  benchmark::Shutdown();
  return 0;
}
