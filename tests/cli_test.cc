// The `tessera` executable as users run it: exit codes and one-line messages.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <fstream>

#include "test_support.h"

namespace tessera {
namespace {

struct CommandResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr together
};

// `environment` is prepended to the command, e.g. "TESSERA_PLUGIN_PATH=/x".
CommandResult RunTessera(const std::string& arguments, const std::string& environment = "") {
  const std::string command =
      environment + " " + std::string(TESSERA_TEST_EXECUTABLE) + " " + arguments + " 2>&1";
  CommandResult result;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return result;
  std::array<char, 4096> buffer;
  size_t n;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
    result.output.append(buffer.data(), n);
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

TEST(Cli, PrintsItsVersion) {
  const auto result = RunTessera("--version");
  EXPECT_EQ(result.exit_code, 0);
  EXPECT_NE(result.output.find("0."), std::string::npos) << result.output;
}

TEST(Cli, BadArgumentsAreExitCode2) {
  EXPECT_EQ(RunTessera("").exit_code, 2);
  EXPECT_EQ(RunTessera("frobnicate").exit_code, 2);
  EXPECT_EQ(RunTessera("run --output /tmp/x").exit_code, 2);  // --images missing
}

TEST(Cli, PluginsJsonListsEveryBundledPluginWithKindAndVersion) {
  const auto result = RunTessera("plugins --json");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const auto json = nlohmann::json::parse(result.output);
  std::map<std::string, std::string> kinds;
  for (const auto& plugin : json["plugins"]) {
    EXPECT_TRUE(plugin["usable"].get<bool>()) << plugin.dump();
    EXPECT_FALSE(plugin["version"].get<std::string>().empty());
    kinds[plugin["name"].get<std::string>()] = plugin["kind"].get<std::string>();
  }
  const std::map<std::string, std::string> expected = {{"sift", "detector"},
                                                       {"orb", "detector"},
                                                       {"brute_force", "matcher"},
                                                       {"flann", "matcher"},
                                                       {"exhaustive", "pair_selector"},
                                                       {"sequential", "pair_selector"},
                                                       {"window", "pair_selector"},
                                                       {"window_anchor", "pair_selector"},
                                                       {"ceres", "bundle_adjuster"}};
  for (const auto& [name, kind] : expected) {
    ASSERT_TRUE(kinds.count(name)) << "bundled plugin '" << name << "' not listed";
    EXPECT_EQ(kinds[name], kind) << name;
  }
}

TEST(Cli, PluginsMarksRefusedFilesWithWhy) {
  const std::string path = std::string(TESSERA_TEST_PLUGIN_ROOT) + "/wrong_abi";
  const auto with_broken = RunTessera("plugins", "TESSERA_PLUGIN_PATH=" + path);
  EXPECT_EQ(with_broken.exit_code, 0);
  EXPECT_NE(with_broken.output.find("REFUSED " + path), std::string::npos) << with_broken.output;
  EXPECT_NE(with_broken.output.find("got version 999, supported version is 1"), std::string::npos);
}

TEST(Cli, MisspeltPluginFailsBeforeReadingImagesWithASuggestion) {
  testing::TemporaryDir dir;
  const auto manifest = dir.path() / "typo.json";
  std::ofstream(manifest) << R"({"pipeline": {"detector": {"plugin": "sift"},
                                               "pair_selector": {"plugin": "exhaustive"},
                                               "matcher": {"plugin": "flan"}}})";
  // The image folder does not exist: the manifest error must come first.
  const auto result =
      RunTessera("run --images " + (dir.path() / "no_such_folder").string() + " --output " +
                 (dir.path() / "out").string() + " --manifest " + manifest.string());
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find(manifest.string() +
                               ": pipeline.matcher.plugin: no matcher plugin 'flan'; did you mean "
                               "'flann'?"),
            std::string::npos)
      << result.output;
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "out" / "database.db"));
}

TEST(Cli, InvalidPluginOptionIsExitCode2) {
  testing::TemporaryDir dir;
  const auto manifest = dir.path() / "bad.json";
  std::ofstream(manifest) << R"({"pipeline": {"detector": {"plugin": "sift",
                                 "options": {"max_num_featurs": 10}}}})";
  const auto result =
      RunTessera("extract --images /nonexistent --output " + (dir.path() / "out").string() +
                 " --manifest " + manifest.string());
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find("pipeline.detector.options.max_num_featurs: unknown key; did you "
                               "mean 'max_num_features'?"),
            std::string::npos)
      << result.output;
}

TEST(Cli, TooFewImagesIsExitCode2) {
  testing::TemporaryDir dir;
  std::filesystem::create_directories(dir.path() / "images");
  std::ofstream(dir.path() / "images" / "notes.txt") << "not an image";
  const auto result = RunTessera("extract --images " + (dir.path() / "images").string() +
                                 " --output " + (dir.path() / "out").string());
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find("0 usable image(s); at least 2 are needed"), std::string::npos)
      << result.output;
}

TEST(Cli, MissingManifestIsExitCode2) {
  const auto result =
      RunTessera("run --images /tmp --output /tmp/out --manifest /nonexistent/m.json");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.output.find("/nonexistent/m.json: cannot read the manifest"), std::string::npos)
      << result.output;
}

}  // namespace
}  // namespace tessera
