#include "distributed/slurm.h"

#include <gtest/gtest.h>

#include <fstream>
#include <functional>

#include "pipeline/stage_test_util.h"
#include "tessera/errors.h"

namespace tessera {
namespace {

SlurmOptions Options() {
  SlurmOptions options;
  options.tessera = "/opt/tessera/bin/tessera";
  options.image_dir = "/shared/photos";
  options.output_dir = "/shared/out";
  options.manifest = "/shared/m.json";
  options.workers = 4;
  options.threads = 8;
  options.partition = "cpu";
  options.time = "02:00:00";
  options.sbatch_args = {"--account=sfm"};
  return options;
}

const SlurmScript& Named(const std::vector<SlurmScript>& scripts, const std::string& name) {
  for (const SlurmScript& script : scripts) {
    if (script.name == name) return script;
  }
  throw std::runtime_error("no script " + name);
}

bool Has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(Slurm, ArraySpecs) {
  EXPECT_EQ(ArraySpec({0, 1, 2, 3}), "0-3");
  EXPECT_EQ(ArraySpec({2}), "2");
  EXPECT_EQ(ArraySpec({0, 2, 5}), "0,2,5");
}

TEST(Slurm, ShellQuoting) {
  EXPECT_EQ(ShellQuote("/a b/c"), "'/a b/c'");
  EXPECT_EQ(ShellQuote("it's"), "'it'\\''s'");
}

// A line break in any value would end its #SBATCH line: what follows would run as a
// shell line, and the #SBATCH lines after it (--kill-on-invalid-dep) would not count.
TEST(Slurm, ControlCharactersInAnyScriptValueAreRefusedNamingTheOption) {
  struct Case {
    std::string option;
    std::function<void(SlurmOptions*)> change;
    std::string shown;  // the value in the message
  };
  const std::vector<Case> cases = {
      {"--partition", [](SlurmOptions* o) { o->partition = "cpu\ntouch /tmp/pwned"; },
       "'cpu\\ntouch /tmp/pwned'"},
      {"--time", [](SlurmOptions* o) { o->time = "01:00:00\r"; }, "'01:00:00\\r'"},
      {"--sbatch-arg", [](SlurmOptions* o) { o->sbatch_args.push_back("--qos=x\ntouch y"); },
       "'--qos=x\\ntouch y'"},
      {"--output", [](SlurmOptions* o) { o->output_dir = "/shared/out\ntouch y"; },
       "'/shared/out\\ntouch y'"},
      {"--images", [](SlurmOptions* o) { o->image_dir = "/shared/\x1b[2J"; }, "'/shared/\\x1b[2J'"},
      {"--manifest", [](SlurmOptions* o) { o->manifest = "/shared/m\t.json"; },
       "'/shared/m\\t.json'"},
      {"--camera-K", [](SlurmOptions* o) { o->camera_K = "/shared/K\n.txt"; },
       "'/shared/K\\n.txt'"},
      {"the tessera executable", [](SlurmOptions* o) { o->tessera = "/opt/t\nessera"; },
       "'/opt/t\\nessera'"},
  };
  for (const Case& c : cases) {
    SlurmOptions options = Options();
    c.change(&options);
    try {
      MakeSlurmScripts(options, {{0}, {0}});
      ADD_FAILURE() << "expected InputError for " << c.option;
    } catch (const InputError& error) {
      EXPECT_EQ(std::string(error.what()),
                c.option + " " + c.shown +
                    ": holds a control character; a value written into the Slurm batch scripts "
                    "must be one line of text.");
    }
  }
}

// Paths are one word however they are spelt: in the shell lines (bash runs them here,
// printing its arguments) and in the #SBATCH --output line (sbatch's own quoting, and
// %% for a % of the path, which Slurm would take for a replacement).
TEST(Slurm, PathsWithSpacesQuotesAndDollarsStayOneWord) {
  SlurmOptions options = Options();
  options.image_dir = "/shared/my photos/it's $HOME `id` \"q\" \\ #1";
  options.output_dir = "/shared/out $(id) 100%";
  options.camera_K = "/shared/K file.txt";
  options.camera_per_folder = true;
  const std::string extract = Named(MakeSlurmScripts(options, {{0, 1}, {0, 1}}), "extract").text;
  EXPECT_TRUE(
      Has(extract, "#SBATCH --output=\"/shared/out $(id) 100%%/slurm/logs/extract-%a-%j.log\"\n"))
      << extract;
  const std::string exec = "exec '/opt/tessera/bin/tessera' ";
  const size_t begin = extract.find(exec);
  ASSERT_NE(begin, std::string::npos) << extract;
  const std::string command =
      "SLURM_ARRAY_TASK_ID=1; printf '%s\\n' " + extract.substr(begin + exec.size());
  const testing::CommandResult printed = testing::RunCommand("bash -c", ShellQuote(command));
  EXPECT_EQ(printed.exit_code, 0) << printed.output;
  EXPECT_EQ(printed.output, "extract\n--images\n" + options.image_dir.string() + "\n--output\n" +
                                options.output_dir.string() +
                                "\n--manifest\n/shared/m.json\n--threads\n8\n--camera-K\n"
                                "/shared/K file.txt\n--camera-per-folder\n--shard\n1/4\n");
  EXPECT_EQ(SbatchQuote("cpu"), "cpu");
  EXPECT_EQ(SbatchQuote("a b\"c\\d#"), "\"a b\\\"c\\\\d#\"");
  EXPECT_EQ(SbatchQuote(""), "\"\"");
}

TEST(Slurm, FiveScriptsInOrderWithArraysAndOptions) {
  const std::vector<SlurmScript> scripts =
      MakeSlurmScripts(Options(), {{0, 1, 2, 3}, {0, 1, 2, 3}});
  ASSERT_EQ(scripts.size(), 5u);
  const std::vector<std::string> names = {"extract", "merge_extract", "match", "merge_match",
                                          "map"};
  for (size_t i = 0; i < names.size(); ++i) {
    EXPECT_EQ(scripts[i].name, names[i]);
    EXPECT_EQ(scripts[i].path, std::filesystem::path("/shared/out/slurm") / (names[i] + ".sh"));
    const std::string& text = scripts[i].text;
    EXPECT_EQ(text.rfind("#!/bin/bash\n", 0), 0u);
    EXPECT_TRUE(Has(text, "#SBATCH --partition=cpu\n")) << text;
    EXPECT_TRUE(Has(text, "#SBATCH --time=02:00:00\n")) << text;
    EXPECT_TRUE(Has(text, "#SBATCH --account=sfm\n")) << text;
    EXPECT_TRUE(Has(text, "#SBATCH --cpus-per-task=8\n")) << text;
    EXPECT_TRUE(Has(text, "#SBATCH --kill-on-invalid-dep=yes\n")) << text;
    EXPECT_TRUE(Has(text, "exec '/opt/tessera/bin/tessera' ")) << text;
  }
  const std::string& extract = Named(scripts, "extract").text;
  EXPECT_TRUE(Has(extract, "#SBATCH --array=0-3\n")) << extract;
  EXPECT_TRUE(Has(extract,
                  "extract --images '/shared/photos' --output '/shared/out' --manifest "
                  "'/shared/m.json' --threads 8 --shard \"$SLURM_ARRAY_TASK_ID/4\""))
      << extract;
  EXPECT_TRUE(Has(extract, "#SBATCH --output=/shared/out/slurm/logs/extract-%a-%j.log")) << extract;
  EXPECT_TRUE(Has(Named(scripts, "merge_extract").text,
                  "merge --output '/shared/out' --stage extract --shards 4"));
  EXPECT_TRUE(Has(Named(scripts, "match").text, "match --output '/shared/out'"));
  EXPECT_TRUE(Has(Named(scripts, "merge_match").text, "--stage match --shards 4"));
  EXPECT_TRUE(Has(Named(scripts, "map").text, "map --images '/shared/photos' --output"));
  EXPECT_FALSE(Has(Named(scripts, "map").text, "--array"));
}

TEST(Slurm, PartitionedMappingIsAPartitionJobAClusterArrayAndTheMerge) {
  SlurmOptions options = Options();
  options.partitioned = true;
  const std::vector<SlurmScript> scripts = MakeSlurmScripts(options, {{}, {}});
  std::vector<std::string> names;
  for (const SlurmScript& script : scripts) names.push_back(script.name);
  EXPECT_EQ(names, (std::vector<std::string>{"merge_extract", "merge_match", "partition", "map",
                                             "merge_map"}));
  EXPECT_TRUE(Has(Named(scripts, "partition").text,
                  "partition --output '/shared/out' --manifest '/shared/m.json'\n"));
  const std::string& map = Named(scripts, "map").text;
  EXPECT_TRUE(Has(map, "#SBATCH --array=0-3\n")) << map;
  EXPECT_TRUE(Has(map,
                  "map --images '/shared/photos' --output '/shared/out' --manifest "
                  "'/shared/m.json' --threads 8 --cluster-shard \"$SLURM_ARRAY_TASK_ID/4\""))
      << map;
  EXPECT_TRUE(Has(Named(scripts, "merge_map").text,
                  "merge --stage map --images '/shared/photos' --output '/shared/out' --manifest "
                  "'/shared/m.json'\n"));
}

TEST(Slurm, ARerunHasOnlyTheUnfinishedShards) {
  const std::vector<SlurmScript> scripts = MakeSlurmScripts(Options(), {{}, {1, 3}});
  ASSERT_EQ(scripts.size(), 4u);
  EXPECT_EQ(scripts[0].name, "merge_extract");
  EXPECT_TRUE(Has(Named(scripts, "match").text, "#SBATCH --array=1,3\n"));
}

TEST(Slurm, ScriptsAreWrittenExecutable) {
  testing::TemporaryDir dir;
  SlurmOptions options = Options();
  options.output_dir = dir.path() / "out";
  WriteSlurmScripts(MakeSlurmScripts(options, {{0}, {0}}));
  const std::filesystem::path extract = dir.path() / "out" / "slurm" / "extract.sh";
  ASSERT_TRUE(std::filesystem::exists(extract));
  EXPECT_NE(std::filesystem::status(extract).permissions() & std::filesystem::perms::owner_exec,
            std::filesystem::perms::none);
  EXPECT_TRUE(std::filesystem::is_directory(dir.path() / "out" / "slurm" / "logs"));
}

// OUTPUT/slurm a link to another folder: no script is written through it.
TEST(Slurm, NoScriptIsWrittenThroughALink) {
  testing::TemporaryDir dir;
  SlurmOptions options = Options();
  options.output_dir = dir.path() / "out";
  std::filesystem::create_directories(dir.path() / "elsewhere");
  std::filesystem::create_directories(options.output_dir);
  std::filesystem::create_directory_symlink(dir.path() / "elsewhere", options.output_dir / "slurm");
  try {
    WriteSlurmScripts(MakeSlurmScripts(options, {{0}, {0}}));
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_TRUE(Has(error.what(), (options.output_dir / "slurm").string() + ", a symbolic link"))
        << error.what();
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir.path() / "elsewhere"));
}

// A stand-in for sbatch: records each call's arguments, one per line, and answers as
// sbatch --parsable does ("id;cluster" first, then "id"), or refuses a script named
// "bad" on stderr.
std::filesystem::path FakeSbatch(const std::filesystem::path& dir) {
  const std::filesystem::path sbatch = dir / "sbatch";
  const std::string calls = (dir / "calls").string(), first = (dir / "first").string();
  std::ofstream(sbatch) << "#!/bin/sh\n"
                        << "printf '%s\\n' \"$@\" --- >> '" << calls << "'\n"
                        << "for script; do :; done\n"  // the last argument
                        << "case \"$script\" in *bad.sh)\n"
                        << "  echo 'sbatch: error: Batch job submission failed' >&2; exit 1;;\n"
                        << "esac\n"
                        << "if [ -f '" << first << "' ]; then echo 18; exit 0; fi\n"
                        << "touch '" << first << "'; echo '17;cluster'\n";
  std::filesystem::permissions(sbatch, std::filesystem::perms::owner_all);
  return sbatch;
}

TEST(Slurm, ScriptsAreSubmittedInOrderEachAfterThePreviousOne) {
  testing::TemporaryDir dir;
  const std::filesystem::path sbatch = FakeSbatch(dir.path());
  // A path sbatch gets as one argument, whatever it holds.
  const std::filesystem::path odd = dir.path() / "it's a $HOME";
  const std::vector<std::string> ids = SubmitSlurmScripts(
      sbatch, {{"extract", odd / "extract.sh", ""}, {"merge_extract", odd / "merge.sh", ""}});
  EXPECT_EQ(ids, (std::vector<std::string>{"17", "18"}));
  std::ifstream calls(dir.path() / "calls");
  const std::string text((std::istreambuf_iterator<char>(calls)), {});
  EXPECT_EQ(text, "--parsable\n" + (odd / "extract.sh").string() +
                      "\n---\n--parsable\n--dependency=afterok:17\n" + (odd / "merge.sh").string() +
                      "\n---\n");
}

TEST(Slurm, ARefusedScriptIsAnInputErrorWithWhatSbatchSaid) {
  testing::TemporaryDir dir;
  const std::filesystem::path sbatch = FakeSbatch(dir.path());
  const std::filesystem::path bad = dir.path() / "bad.sh";
  try {
    SubmitSlurmScripts(sbatch, {{"extract", dir.path() / "extract.sh", ""}, {"bad", bad, ""}});
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()), sbatch.string() + " refused " + bad.string() +
                                             ": sbatch: error: Batch job submission failed");
  }
}

// The verbs' arguments, as a user gives them.
class DistributedArguments : public ::testing::Test {
 protected:
  testing::CommandResult Tessera(const std::string& arguments, const std::string& env = "") {
    return testing::RunCommand(TESSERA_TEST_EXECUTABLE, arguments, env);
  }
  testing::TemporaryDir dir_;
};

TEST_F(DistributedArguments, AShardOutsideTheRangeIsExit2) {
  testing::WriteSampleImages(dir_.path() / "images", 2);
  const std::string images = (dir_.path() / "images").string();
  const std::string out = (dir_.path() / "out").string();
  for (const char* shard : {"3/3", "0/0", "-1/2", "x"}) {
    const auto result = Tessera(std::string("extract --images ") + images + " --output " + out +
                                " --shard " + shard);
    EXPECT_EQ(result.exit_code, 2) << shard << ": " << result.output;
    EXPECT_TRUE(Has(result.output, "--shard")) << result.output;
    const auto match = Tessera("match --output " + out + " --shard " + shard);
    EXPECT_EQ(match.exit_code, 2) << match.output;
  }
  EXPECT_FALSE(std::filesystem::exists(dir_.path() / "out" / "shards"));
  const auto workers = Tessera("slurm --images " + images + " --output " + out + " --workers 0");
  EXPECT_EQ(workers.exit_code, 2) << workers.output;
}

TEST_F(DistributedArguments, ALineBreakInAnOptionIsExit2BeforeAnythingIsWritten) {
  const std::string images = (dir_.path() / "images").string();
  const std::string out = (dir_.path() / "out").string();
  for (const std::string option : {"--partition", "--sbatch-arg", "--time"}) {
    const auto result =
        Tessera("slurm --images " + images + " --output " + out + " --workers 2 --dry-run " +
                option + " " + ShellQuote("x\ntouch " + (dir_.path() / "pwned").string()));
    EXPECT_EQ(result.exit_code, 2) << result.output;
    EXPECT_TRUE(Has(result.output, option + " 'x\\ntouch ")) << result.output;
  }
  const auto output = Tessera("slurm --images " + images + " --output " + ShellQuote(out + "\nx") +
                              " --workers 2 --dry-run");
  EXPECT_EQ(output.exit_code, 2) << output.output;
  EXPECT_TRUE(Has(output.output, "--output '" + out + "\\nx': holds a control character"))
      << output.output;
  EXPECT_FALSE(std::filesystem::exists(dir_.path() / "out"));
  EXPECT_FALSE(std::filesystem::exists(dir_.path() / "pwned"));
}

TEST_F(DistributedArguments, SbatchMissingIsExit2SuggestingDryRun) {
  testing::WriteSampleImages(dir_.path() / "images", 2);
  std::ofstream(dir_.path() / "m.json")
      << R"({"pipeline": {"detector": {"plugin": "orb"}, "pair_selector": {"plugin": "exhaustive"},
                          "matcher": {"plugin": "brute_force"}}})";
  const std::string arguments = "slurm --images " + (dir_.path() / "images").string() +
                                " --output " + (dir_.path() / "out").string() +
                                " --workers 2 --manifest " + (dir_.path() / "m.json").string();
  const auto result = Tessera(arguments, "PATH=/nonexistent");
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_TRUE(Has(result.output, "sbatch")) << result.output;
  EXPECT_TRUE(Has(result.output, "--dry-run")) << result.output;
  const auto dry = Tessera(arguments + " --dry-run", "PATH=/nonexistent");
  EXPECT_EQ(dry.exit_code, 0) << dry.output;
  std::ifstream extract(dir_.path() / "out" / "slurm" / "extract.sh");
  const std::string text((std::istreambuf_iterator<char>(extract)), {});
  EXPECT_TRUE(Has(text, "#SBATCH --array=0-1")) << text;
  EXPECT_FALSE(std::filesystem::exists(dir_.path() / "out" / "database.db"));
}

}  // namespace
}  // namespace tessera
