#pragma once

// `tessera slurm`: the batch scripts of a whole run on a Slurm cluster, written to
// OUTPUT/slurm/ and submitted with sbatch as dependent jobs (afterok):
//   1. extract.sh, a job array of extraction shards;   2. merge_extract.sh;
//   3. match.sh, a job array of matching shards;       4. merge_match.sh;
//   5. map.sh, mapping and the exporters; or, partitioned (docs/distributed_mapping.md):
//      partition.sh, map.sh (a job array: shard K maps clusters K, K+N, ...) and
//      merge_map.sh (the merge of the cluster models and the exporters).
// Only unfinished shards are in the arrays, so submitting again after a failure reruns
// only those. OUTPUT must be on a filesystem every node sees.

#include <filesystem>
#include <string>
#include <vector>

namespace tessera {

struct SlurmOptions {
  std::filesystem::path tessera;  // the executable the jobs run (absolute)
  std::filesystem::path image_dir;
  std::filesystem::path output_dir;
  std::filesystem::path manifest;        // empty: the default manifest
  std::filesystem::path camera_K;        // empty: none
  bool camera_per_folder = false;        // extract --camera-per-folder
  int workers = 1;                       // N, the shards of each stage
  int threads = 0;                       // per task (--cpus-per-task); 0: Slurm's default
  std::string partition;                 // empty: the cluster's default
  std::string time;                      // empty: the partition's default
  std::vector<std::string> sbatch_args;  // more #SBATCH lines, e.g. --account=foo
  bool partitioned = false;              // mapping as clusters (partition/)
};

// The jobs to submit; an empty array is left out (its stage is done).
struct SlurmPlan {
  std::vector<int> extract_shards;  // unfinished extraction shards
  std::vector<int> match_shards;    // unfinished matching shards
};

struct SlurmScript {
  std::string name;  // "extract", "merge_extract", "match", "merge_match", "map"
  std::filesystem::path path;
  std::string text;
};

// Throws InputError naming the option (--output, --partition, --sbatch-arg, ...) and its
// value, control characters escaped, when a value written into the batch scripts holds a
// control character: a line break would end its #SBATCH line, and what follows would run
// as shell lines or stop sbatch reading the #SBATCH lines after it.
void CheckSlurmOptions(const SlurmOptions& options);

// The scripts for `plan` (the absolute paths of options are used as given). Calls
// CheckSlurmOptions first.
std::vector<SlurmScript> MakeSlurmScripts(const SlurmOptions& options, const SlurmPlan& plan);

// "0-3", or "0,2,5" for a rerun.
std::string ArraySpec(const std::vector<int>& indices);

// Quotes a word for bash.
std::string ShellQuote(const std::string& word);

// Quotes a word for an #SBATCH line as sbatch splits it (whitespace between arguments,
// quotes group, a backslash escapes, an unquoted # starts a comment): as it is when it
// holds none of those, else in double quotes with \ and " escaped.
std::string SbatchQuote(const std::string& word);

// Writes the scripts (executable) into OUTPUT/slurm/ and creates OUTPUT/slurm/logs/.
// Throws InputError naming the path it cannot write.
void WriteSlurmScripts(const std::vector<SlurmScript>& scripts);

// Submits the scripts in order with `sbatch --parsable` (util/child_process.h's RunChild;
// `sbatch` a path, FindOnPath), each after the previous one (--dependency=afterok);
// returns the job ids. Throws InputError when sbatch refuses, with what it said.
std::vector<std::string> SubmitSlurmScripts(const std::filesystem::path& sbatch,
                                            const std::vector<SlurmScript>& scripts);

}  // namespace tessera
