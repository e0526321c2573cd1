#include "distributed/slurm.h"

#include <cstring>

#include "io/names.h"
#include "tessera/errors.h"
#include "tessera/io/file_io.h"
#include "util/child_process.h"
#include "util/workspace_layout.h"

namespace tessera {
namespace {

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

std::string CommonArgs(const SlurmOptions& options) {
  std::string args = " --output " + ShellQuote(options.output_dir.string());
  if (!options.manifest.empty()) args += " --manifest " + ShellQuote(options.manifest.string());
  if (options.threads > 0) args += " --threads " + std::to_string(options.threads);
  return args;
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
  const std::string tessera = ShellQuote(options.tessera.string());
  const std::string images = ShellQuote(options.image_dir.string());
  const std::string n = std::to_string(options.workers);
  const std::string common = CommonArgs(options);
  const std::string camera_K =
      (options.camera_K.empty() ? "" : " --camera-K " + ShellQuote(options.camera_K.string())) +
      (options.camera_per_folder ? " --camera-per-folder" : "");
  const std::string shard = " --shard \"$SLURM_ARRAY_TASK_ID/" + n + "\"";
  std::vector<SlurmScript> scripts;
  const auto add = [&](const std::string& name, bool array, const std::vector<int>& indices,
                       const std::string& command) {
    std::string text = Header(options, name, array);
    if (array)
      text.insert(text.find("#SBATCH --output"), "#SBATCH --array=" + ArraySpec(indices) + "\n");
    text += "exec " + tessera + " " + command + "\n";
    scripts.push_back(
        {name, options.output_dir / workspace_layout::kSlurmFolder / (name + ".sh"), text});
  };
  if (!plan.extract_shards.empty()) {
    add("extract", true, plan.extract_shards,
        "extract --images " + images + common + camera_K + shard);
  }
  add("merge_extract", false, {},
      "merge --output " + ShellQuote(options.output_dir.string()) + " --stage extract --shards " +
          n);
  if (!plan.match_shards.empty()) {
    add("match", true, plan.match_shards, "match" + common + shard);
  }
  add("merge_match", false, {},
      "merge --output " + ShellQuote(options.output_dir.string()) + " --stage match --shards " + n);
  if (!options.partitioned) {
    add("map", false, {}, "map --images " + images + common);
    return scripts;
  }
  // The number of clusters is known only once partition has run: shard K of N maps
  // clusters K, K+N, ..., each skipped when already mapped, so a rerun maps what is left.
  std::string manifest;
  if (!options.manifest.empty()) manifest = " --manifest " + ShellQuote(options.manifest.string());
  add("partition", false, {},
      "partition --output " + ShellQuote(options.output_dir.string()) + manifest);
  std::vector<int> all(static_cast<size_t>(options.workers));
  for (int k = 0; k < options.workers; ++k) all[static_cast<size_t>(k)] = k;
  add("map", true, all,
      "map --images " + images + common + " --cluster-shard \"$SLURM_ARRAY_TASK_ID/" + n + "\"");
  add("merge_map", false, {},
      "merge --stage map --images " + images + " --output " +
          ShellQuote(options.output_dir.string()) + manifest);
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
    const ChildRun run = RunChild(argv);  // its stdout and stderr, together
    if (!run.started) {
      throw InputError(sbatch.string() + ": cannot run it to submit " + script.path.string() +
                       ": " + std::strerror(run.error));
    }
    std::string output = run.output;
    while (!output.empty() && (output.back() == '\n' || output.back() == '\r')) output.pop_back();
    if (run.exit_code != 0 || output.empty()) {
      throw InputError(sbatch.string() + " refused " + script.path.string() + ": " + output);
    }
    // --parsable prints "id" or "id;cluster".
    ids.push_back(output.substr(0, output.find(';')));
  }
  return ids;
}

}  // namespace tessera
