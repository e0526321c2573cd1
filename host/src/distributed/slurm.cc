#include "distributed/slurm.h"

#include <cstring>

#include "io/names.h"
#include "tessera/errors.h"
#include "tessera/io/file_io.h"
#include "util/child_process.h"
#include "util/strings.h"
#include "util/tessera_commands.h"
#include "util/workspace_layout.h"

namespace tessera {
namespace {

// sbatch answers at once or not at all (a controller that does not respond).
constexpr double kSbatchTimeoutSeconds = 120;

// `path` in a Slurm filename pattern, where % starts a replacement (%j, %a): %% is a %.
std::string PercentEscaped(const std::string& path) {
  std::string escaped;
  for (const char c : path) escaped += c == '%' ? std::string("%%") : std::string(1, c);
  return escaped;
}

std::string Header(const SlurmOptions& options, const std::string& name, bool array) {
  const std::filesystem::path logs = options.output_dir / workspace_layout::kSlurmFolder / "logs";
  std::string text = "#!/bin/bash\n";
  text += "#SBATCH --job-name=tessera-" + name + "\n";
  text +=
      "#SBATCH --output=" +
      SbatchQuote(PercentEscaped(logs.string()) + "/" + name + (array ? "-%a" : "") + "-%j.log") +
      "\n";
  if (options.threads > 0)
    text += "#SBATCH --cpus-per-task=" + std::to_string(options.threads) + "\n";
  if (!options.partition.empty()) {
    text += "#SBATCH --partition=" + SbatchQuote(options.partition) + "\n";
  }
  if (!options.time.empty()) text += "#SBATCH --time=" + SbatchQuote(options.time) + "\n";
  // A job whose dependency failed is cancelled instead of waiting for ever.
  text += "#SBATCH --kill-on-invalid-dep=yes\n";
  for (const std::string& arg : options.sbatch_args) text += "#SBATCH " + arg + "\n";
  text += "set -euo pipefail\n";
  return text;
}

// A word of a script's command line: as it is when the shell reads it so (a verb, an
// option, a number), else in single quotes.
std::string ScriptWord(const std::string& word) {
  const bool plain = !word.empty() && word.find_first_not_of(
                                          "abcdefghijklmnopqrstuvwxyz"
                                          "0123456789-_") == std::string::npos;
  return plain ? word : ShellQuote(word);
}

void CheckScriptValue(const std::string& option, const std::string& value) {
  if (!HasControlCharacter(value)) return;
  throw InputError(option + " '" + EscapeControlCharacters(value) +
                   "': holds a control character; a value written into the Slurm batch "
                   "scripts must be one line of text.");
}

}  // namespace

void CheckSlurmOptions(const SlurmOptions& options) {
  CheckScriptValue("the tessera executable", options.tessera.string());
  CheckScriptValue("--images", options.image_dir.string());
  CheckScriptValue("--output", options.output_dir.string());
  CheckScriptValue("--manifest", options.manifest.string());
  CheckScriptValue("--camera-K", options.camera_K.string());
  CheckScriptValue("--partition", options.partition);
  CheckScriptValue("--time", options.time);
  for (const std::string& arg : options.sbatch_args) CheckScriptValue("--sbatch-arg", arg);
}

std::string SbatchQuote(const std::string& word) {
  if (!word.empty() && word.find_first_of(" \t\v\f\"'\\#") == std::string::npos) return word;
  std::string quoted = "\"";
  for (const char c : word) {
    if (c == '"' || c == '\\') quoted += '\\';
    quoted += c;
  }
  return quoted + "\"";
}

std::string ShellQuote(const std::string& word) {
  std::string quoted = "'";
  for (const char c : word) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

std::string ArraySpec(const std::vector<int>& indices) {
  bool contiguous = !indices.empty();
  for (size_t i = 1; i < indices.size(); ++i) contiguous &= indices[i] == indices[i - 1] + 1;
  if (contiguous && indices.size() > 1) {
    return std::to_string(indices.front()) + "-" + std::to_string(indices.back());
  }
  std::string spec;
  for (const int index : indices) spec += (spec.empty() ? "" : ",") + std::to_string(index);
  return spec;
}

std::vector<SlurmScript> MakeSlurmScripts(const SlurmOptions& options, const SlurmPlan& plan) {
  CheckSlurmOptions(options);
  SlurmJobArguments arguments;
  arguments.tessera = options.tessera;
  arguments.image_dir = options.image_dir;
  arguments.output_dir = options.output_dir;
  arguments.manifest = options.manifest;
  arguments.camera_K = options.camera_K;
  arguments.camera_per_folder = options.camera_per_folder;
  arguments.workers = options.workers;
  arguments.threads = options.threads;
  const std::string task_shard = "$SLURM_ARRAY_TASK_ID/" + std::to_string(options.workers);
  std::vector<SlurmScript> scripts;
  const auto add = [&](const std::string& name, SlurmJob job, const std::vector<int>& indices) {
    const bool array = IsSlurmArrayJob(job);
    std::string text = Header(options, name, array);
    if (array)
      text.insert(text.find("#SBATCH --output"), "#SBATCH --array=" + ArraySpec(indices) + "\n");
    const std::vector<std::string> argv = SlurmJobCommand(arguments, job, task_shard);
    text += "exec";
    for (size_t k = 0; k < argv.size(); ++k) {
      // The shard word, last, in double quotes: the shell expands $SLURM_ARRAY_TASK_ID.
      text += " " + (array && k + 1 == argv.size() ? "\"" + argv[k] + "\"" : ScriptWord(argv[k]));
    }
    text += "\n";
    scripts.push_back(
        {name, options.output_dir / workspace_layout::kSlurmFolder / (name + ".sh"), text});
  };
  if (!plan.extract_shards.empty()) add("extract", SlurmJob::kExtract, plan.extract_shards);
  add("merge_extract", SlurmJob::kMergeExtract, {});
  if (!plan.match_shards.empty()) add("match", SlurmJob::kMatch, plan.match_shards);
  add("merge_match", SlurmJob::kMergeMatch, {});
  if (!options.partitioned) {
    add("map", SlurmJob::kMap, {});
    return scripts;
  }
  // The number of clusters is known only once partition has run: shard K of N maps
  // clusters K, K+N, ..., each skipped when already mapped, so a rerun maps what is left.
  add("partition", SlurmJob::kPartition, {});
  std::vector<int> all(static_cast<size_t>(options.workers));
  for (int k = 0; k < options.workers; ++k) all[static_cast<size_t>(k)] = k;
  add("map", SlurmJob::kMapClusters, all);
  add("merge_map", SlurmJob::kMergeMap, {});
  return scripts;
}

void WriteSlurmScripts(const std::vector<SlurmScript>& scripts) {
  for (const SlurmScript& script : scripts) {
    std::error_code error;
    // OUTPUT/slurm/: nothing is written through a link (Tessera makes none).
    const std::filesystem::path folder = script.path.parent_path();
    CheckPathBelow(folder.parent_path(), (folder.filename() / script.path.filename()).string(),
                   script.path.string());
    std::filesystem::create_directories(script.path.parent_path() / "logs", error);
    if (error) {
      throw InputError((script.path.parent_path() / "logs").string() +
                       ": cannot create the folder: " + error.message());
    }
    WriteFileAtomically(script.path, script.text);
    std::filesystem::permissions(script.path,
                                 std::filesystem::perms::owner_exec |
                                     std::filesystem::perms::group_exec |
                                     std::filesystem::perms::others_exec,
                                 std::filesystem::perm_options::add, error);
  }
}

std::vector<std::string> SubmitSlurmScripts(const std::filesystem::path& sbatch,
                                            const std::vector<SlurmScript>& scripts) {
  std::vector<std::string> ids;
  for (const SlurmScript& script : scripts) {
    std::vector<std::string> argv = {sbatch.string(), "--parsable"};
    if (!ids.empty()) argv.push_back("--dependency=afterok:" + ids.back());
    argv.push_back(script.path.string());
    RunChildOptions child;
    child.timeout_seconds = kSbatchTimeoutSeconds;
    const ChildRun run = RunChild(argv, child);  // its stdout and stderr, together
    if (!run.started) {
      throw InputError(sbatch.string() + ": cannot run it to submit " + script.path.string() +
                       ": " + std::strerror(run.error));
    }
    if (run.timed_out) {
      throw InputError(sbatch.string() + ": no answer within " +
                       std::to_string(static_cast<int>(kSbatchTimeoutSeconds)) +
                       " s to the submission of " + script.path.string());
    }
    std::string output = run.output;
    while (!output.empty() && (output.back() == '\n' || output.back() == '\r')) output.pop_back();
    if (run.exit_code != 0 || output.empty()) {
      throw InputError(sbatch.string() + " refused " + script.path.string() + ": " +
                       PrintableExcerpt(output, 400));
    }
    // --parsable prints "id" or "id;cluster".
    ids.push_back(output.substr(0, output.find(';')));
  }
  return ids;
}

}  // namespace tessera
