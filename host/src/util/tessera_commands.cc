#include "util/tessera_commands.h"

namespace tessera {
namespace {

// Appends `flag value` when the value is not empty.
void AddPath(const char* flag, const std::filesystem::path& value, std::vector<std::string>* argv) {
  if (value.empty()) return;
  argv->push_back(flag);
  argv->push_back(value.string());
}

void AddThreads(int threads, std::vector<std::string>* argv) {
  if (threads <= 0) return;
  argv->push_back("--threads");
  argv->push_back(std::to_string(threads));
}

}  // namespace

std::vector<std::string> BenchRunCommand(const BenchRunArguments& arguments) {
  std::vector<std::string> argv = {
      arguments.tessera.string(), "run",        "--images",        arguments.images, "--output",
      arguments.output.string(),  "--manifest", arguments.manifest};
  AddThreads(arguments.threads, &argv);
  AddPath("--camera-K", arguments.camera_K, &argv);
  if (arguments.camera_per_folder) argv.push_back("--camera-per-folder");
  return argv;
}

std::vector<std::string> MapClusterCommand(const ClusterProcessOptions& options, int cluster) {
  std::vector<std::string> argv = {
      options.tessera.string(), "map",      "--cluster",
      std::to_string(cluster),  "--output", options.output_dir.string()};
  AddPath("--manifest", options.manifest, &argv);
  AddPath("--camera-K", options.camera_K, &argv);
  AddPath("--images", options.image_dir, &argv);
  AddThreads(options.threads, &argv);
  return argv;
}

bool IsSlurmArrayJob(SlurmJob job) {
  return job == SlurmJob::kExtract || job == SlurmJob::kMatch || job == SlurmJob::kMapClusters;
}

std::vector<std::string> SlurmJobCommand(const SlurmJobArguments& arguments, SlurmJob job,
                                         const std::string& task_shard) {
  std::vector<std::string> argv = {arguments.tessera.string()};
  const std::string workers = std::to_string(arguments.workers);
  // --output, --manifest and --threads, as every stage of one run takes them.
  const auto common = [&] {
    AddPath("--output", arguments.output_dir, &argv);
    AddPath("--manifest", arguments.manifest, &argv);
    AddThreads(arguments.threads, &argv);
  };
  const auto images = [&] { AddPath("--images", arguments.image_dir, &argv); };
  switch (job) {
    case SlurmJob::kExtract:
      argv.push_back("extract");
      images();
      common();
      AddPath("--camera-K", arguments.camera_K, &argv);
      if (arguments.camera_per_folder) argv.push_back("--camera-per-folder");
      argv.insert(argv.end(), {"--shard", task_shard});
      break;
    case SlurmJob::kMergeExtract:
    case SlurmJob::kMergeMatch:
      argv.push_back("merge");
      AddPath("--output", arguments.output_dir, &argv);
      argv.insert(argv.end(), {"--stage", job == SlurmJob::kMergeExtract ? "extract" : "match",
                               "--shards", workers});
      break;
    case SlurmJob::kMatch:
      argv.push_back("match");
      common();
      argv.insert(argv.end(), {"--shard", task_shard});
      break;
    case SlurmJob::kMap:
      argv.push_back("map");
      images();
      common();
      break;
    case SlurmJob::kPartition:
      argv.push_back("partition");
      AddPath("--output", arguments.output_dir, &argv);
      AddPath("--manifest", arguments.manifest, &argv);
      break;
    case SlurmJob::kMapClusters:
      argv.push_back("map");
      images();
      common();
      argv.insert(argv.end(), {"--cluster-shard", task_shard});
      break;
    case SlurmJob::kMergeMap:
      argv.insert(argv.end(), {"merge", "--stage", "map"});
      images();
      AddPath("--output", arguments.output_dir, &argv);
      AddPath("--manifest", arguments.manifest, &argv);
      break;
  }
  return argv;
}

}  // namespace tessera
