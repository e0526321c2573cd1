#pragma once

// The command lines of the `tessera` processes that libraries start or write into batch
// scripts, each as an argv: bench's rows (`tessera run`), the cluster processes of `map
// --hierarchical` (`tessera map --cluster K`) and the jobs of `tessera slurm`. The one
// place outside cli/ that writes a `tessera` command line: tests/layout/command_lines_check.py
// fails on any other library source that assembles one.

#include <filesystem>
#include <string>
#include <vector>

namespace tessera {

// What `tessera bench` gives each manifest's `tessera run`.
struct BenchRunArguments {
  std::filesystem::path tessera;  // the executable
  std::string images;
  std::filesystem::path output;  // the row's workspace
  std::string manifest;
  std::string camera_K;  // empty: none
  bool camera_per_folder = false;
  int threads = 0;  // 0: not given
};

// `tessera run --images ... --output ... --manifest ...` for a bench row.
std::vector<std::string> BenchRunCommand(const BenchRunArguments& arguments);

// What a process that maps one cluster (`tessera map --cluster K`) is given beside the
// cluster: the same workspace, images, manifest and intrinsics as the process that starts
// it.
struct ClusterProcessOptions {
  std::filesystem::path tessera;     // the executable
  std::filesystem::path output_dir;  // the workspace
  std::filesystem::path manifest;    // empty: the default manifest
  std::filesystem::path camera_K;    // empty: none
  std::filesystem::path image_dir;   // empty: the folder extract recorded
  int threads = 0;                   // 0: not given (the manifest's, else all cores)
};

// The command line that maps cluster `cluster` in a process of its own (`map
// --hierarchical`'s pool runs it, and a message that advises mapping a cluster again
// prints it).
std::vector<std::string> MapClusterCommand(const ClusterProcessOptions& options, int cluster);

// The jobs of `tessera slurm` (distributed/slurm.h), in the order they are submitted.
enum class SlurmJob {
  kExtract,       // array: extract --shard K/N
  kMergeExtract,  // merge --stage extract
  kMatch,         // array: match --shard K/N
  kMergeMatch,    // merge --stage match
  kMap,           // map (the whole model)
  kPartition,     // partition
  kMapClusters,   // array: map --cluster-shard K/N
  kMergeMap,      // merge --stage map
};

// What every job of `tessera slurm` is given.
struct SlurmJobArguments {
  std::filesystem::path tessera;
  std::filesystem::path image_dir;
  std::filesystem::path output_dir;
  std::filesystem::path manifest;  // empty: the default manifest
  std::filesystem::path camera_K;  // empty: none
  bool camera_per_folder = false;
  int workers = 1;  // N
  int threads = 0;  // 0: not given
};

// Whether `job` runs as a job array: its command line then ends with the shard word.
bool IsSlurmArrayJob(SlurmJob job);

// The command line of `job`; an array job's last word is `task_shard` (the script's
// "$SLURM_ARRAY_TASK_ID/N", which the shell expands).
std::vector<std::string> SlurmJobCommand(const SlurmJobArguments& arguments, SlurmJob job,
                                         const std::string& task_shard);

}  // namespace tessera
