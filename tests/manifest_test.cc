#include "manifest/manifest.h"

#include <gtest/gtest.h>

#include <fstream>

#include "manifest/recipes.h"
#include "tessera/errors.h"
#include "test_support.h"
#include "util/paths.h"

namespace tessera {
namespace {

std::string ErrorOf(const nlohmann::json& json) {
  try {
    Manifest::FromJson(json, "/base", "m.json");
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(Manifest, ParsesSlotsCameraVerificationAndPaths) {
  const nlohmann::json json = {
      {"plugin_paths", {"plugins", "/abs"}},
      {"seed", 7},
      {"threads", 2},
      {"pipeline",
       {{"detector", {{"plugin", "sift"}, {"options", {{"max_num_features", 100}}}}},
        {"matcher", {{"plugin", "flann"}}},
        {"exporters", {{{"plugin", "ply"}}}}}},
      {"camera",
       {{"model", "OPENCV"},
        {"single_camera", false},
        {"per_folder", true},
        {"K", {1000, 1001, 320, 240}},
        {"require_calibration", true}}},
      {"verification", {{"max_error_px", 2.5}}}};
  const Manifest manifest = Manifest::FromJson(json, "/base", "m.json");
  EXPECT_EQ(manifest.plugin_paths, (std::vector<std::filesystem::path>{"/base/plugins", "/abs"}));
  EXPECT_EQ(manifest.seed, 7u);
  EXPECT_EQ(manifest.EffectiveNumThreads(), 2);
  ASSERT_TRUE(manifest.detector);
  EXPECT_EQ(manifest.detector->plugin, "sift");
  EXPECT_EQ(manifest.detector->options["max_num_features"], 100);
  EXPECT_EQ(manifest.detector->json_path, "pipeline.detector");
  EXPECT_TRUE(manifest.pair_selectors.empty());
  ASSERT_EQ(manifest.exporters.size(), 1u);
  EXPECT_EQ(manifest.exporters[0].json_path, "pipeline.exporters[0]");
  EXPECT_EQ(manifest.camera.model, "OPENCV");
  EXPECT_FALSE(manifest.camera.single_camera);
  EXPECT_TRUE(manifest.camera.per_folder);
  EXPECT_FALSE(Manifest::FromJson(nlohmann::json::object(), "/base", "m.json").camera.per_folder);
  ASSERT_TRUE(manifest.camera.known_intrinsics);
  EXPECT_EQ((*manifest.camera.known_intrinsics)(1), 1001);
  EXPECT_EQ(manifest.camera.calibration_required_by, "m.json: camera.require_calibration");
  EXPECT_EQ(Manifest::FromJson(nlohmann::json::object(), "/base", "m.json")
                .camera.calibration_required_by,
            "");
  EXPECT_EQ(manifest.verification.max_error_px, 2.5);
  EXPECT_EQ(manifest.verification.min_num_inliers, 15);
}

TEST(Manifest, TheMapperIsASlotAndIncrementalByDefault) {
  const Manifest plain = Manifest::FromJson(nlohmann::json::object(), "/base", "m.json");
  EXPECT_EQ(plain.mapper.plugin, "incremental");
  EXPECT_EQ(plain.mapper.json_path, "pipeline.mapper");
  EXPECT_FALSE(plain.legacy_mapper_settings);

  const Manifest named = Manifest::FromJson(
      {{"pipeline",
        {{"mapper", {{"plugin", "global"}, {"options", {{"max_num_iterations", 3}}}}}}}},
      "/base", "m.json");
  EXPECT_EQ(named.mapper.plugin, "global");
  EXPECT_EQ(named.mapper.options["max_num_iterations"], 3);
  EXPECT_TRUE(named.mapper.options_path.empty());

  // Manifests of before the mapper kind: the top-level object is the incremental
  // mapper's options, and errors in it keep naming "mapper.KEY".
  const Manifest legacy =
      Manifest::FromJson({{"mapper", {{"min_num_matches", 20}}}}, "/base", "m.json");
  EXPECT_EQ(legacy.mapper.plugin, "incremental");
  EXPECT_EQ(legacy.mapper.options["min_num_matches"], 20);
  EXPECT_EQ(legacy.mapper.options_path, "mapper");
  EXPECT_TRUE(legacy.legacy_mapper_settings);

  const std::string both = ErrorOf({{"mapper", {{"min_num_matches", 20}}},
                                    {"pipeline", {{"mapper", {{"plugin", "incremental"}}}}}});
  EXPECT_NE(both.find("m.json: mapper:"), std::string::npos) << both;
  EXPECT_NE(both.find("pipeline.mapper.options"), std::string::npos) << both;
  EXPECT_NE(ErrorOf({{"mapper", 3}}).find("mapper: expected a JSON object"), std::string::npos);
  EXPECT_NE(ErrorOf({{"pipeline", {{"mapper", {{"options", {}}}}}}}).find("pipeline.mapper"),
            std::string::npos);
}

TEST(Manifest, UnknownKeysNameTheirPathAndTheClosestKey) {
  EXPECT_EQ(ErrorOf({{"pipline", nlohmann::json::object()}}),
            "m.json: pipline: unknown key; did you mean 'pipeline'?");
  EXPECT_EQ(ErrorOf({{"pipeline", {{"matchr", {{"plugin", "flann"}}}}}}),
            "m.json: pipeline.matchr: unknown key; did you mean 'matcher'?");
  EXPECT_EQ(ErrorOf({{"pipeline", {{"matcher", {{"plugn", "flann"}}}}}}),
            "m.json: pipeline.matcher: missing key 'plugin'");
  EXPECT_EQ(ErrorOf({{"camera", {{"per_folder", "yes"}}}}),
            "m.json: camera.per_folder: expected true or false, got a string");
  EXPECT_EQ(ErrorOf({{"camera", {{"modle", "PINHOLE"}}}}),
            "m.json: camera.modle: unknown key; did you mean 'model'?");
  EXPECT_EQ(ErrorOf({{"camera", {{"model", "PINHOL"}}}}),
            "m.json: camera.model: 'PINHOL' is not one of 'SIMPLE_PINHOLE', 'PINHOLE', "
            "'SIMPLE_RADIAL', 'RADIAL', 'OPENCV', 'OPENCV_FISHEYE', 'SIMPLE_RADIAL_FISHEYE'; did "
            "you mean 'PINHOLE'?");
  EXPECT_EQ(ErrorOf({{"verification", {{"max_error_px", -1}}}}),
            "m.json: verification.max_error_px = -1 is out of range [0.1, 100]");
  EXPECT_EQ(ErrorOf({{"threads", "many"}}), "m.json: threads: expected an integer, got a string");
  EXPECT_EQ(ErrorOf({{"camera", {{"K", {1, 2, 3}}}}}),
            "m.json: camera.K: expected [fx, fy, cx, cy] in pixels");
  EXPECT_EQ(ErrorOf({{"camera", {{"model", "OPENCV_FISHEYE"}, {"params", {300, 300, 320, 240}}}}}),
            "m.json: camera.params: OPENCV_FISHEYE takes 8 parameters (fx, fy, cx, cy, k1, k2, "
            "k3, k4), got 4");
  EXPECT_EQ(ErrorOf({{"camera", {{"require_calibration", "yes"}}}}),
            "m.json: camera.require_calibration: expected true or false, got a string");
  EXPECT_EQ(ErrorOf({{"camera", {{"mask_path", 3}}}}),
            "m.json: camera.mask_path: expected a folder path");
}

TEST(Manifest, FisheyeParamsAndMaskPath) {
  const Manifest manifest =
      Manifest::FromJson({{"camera",
                           {{"model", "OPENCV_FISHEYE"},
                            {"params", {300, 310, 320, 240, 0.05, -0.01, 0.002, -0.0005}},
                            {"mask_path", "masks"}}}},
                         "/base", "m.json");
  EXPECT_EQ(manifest.camera.known_params,
            (std::vector<double>{300, 310, 320, 240, 0.05, -0.01, 0.002, -0.0005}));
  ASSERT_TRUE(manifest.camera.known_intrinsics);
  EXPECT_EQ(*manifest.camera.known_intrinsics, Eigen::Vector4d(300, 310, 320, 240));
  EXPECT_EQ(manifest.camera.known_intrinsics_source, "camera.params");
  EXPECT_EQ(manifest.camera.mask_path, std::filesystem::path("/base/masks"));
}

TEST(Manifest, PairSelectorIsOneSlotOrAnArrayOfSlots) {
  const Manifest one = Manifest::FromJson(
      {{"pipeline", {{"pair_selector", {{"plugin", "window"}, {"options", {{"window", 3}}}}}}}},
      "/base", "m.json");
  ASSERT_EQ(one.pair_selectors.size(), 1u);
  EXPECT_EQ(one.pair_selectors[0].plugin, "window");
  EXPECT_EQ(one.pair_selectors[0].options, nlohmann::json({{"window", 3}}));
  EXPECT_EQ(one.pair_selectors[0].json_path, "pipeline.pair_selector");

  const Manifest two = Manifest::FromJson(
      {{"pipeline",
        {{"pair_selector",
          {{{"plugin", "sequential"}}, {{"plugin", "spatial"}, {"options", {{"x", 1}}}}}}}}},
      "/base", "m.json");
  ASSERT_EQ(two.pair_selectors.size(), 2u);
  EXPECT_EQ(two.pair_selectors[0].plugin, "sequential");
  EXPECT_EQ(two.pair_selectors[0].json_path, "pipeline.pair_selector[0]");
  EXPECT_EQ(two.pair_selectors[1].plugin, "spatial");
  EXPECT_EQ(two.pair_selectors[1].json_path, "pipeline.pair_selector[1]");

  EXPECT_EQ(ErrorOf({{"pipeline", {{"pair_selector", nlohmann::json::array()}}}}),
            "m.json: pipeline.pair_selector: expected a slot object or a non-empty array of slot "
            "objects");
  EXPECT_EQ(ErrorOf({{"pipeline",
                      {{"pair_selector", {{{"plugin", "window"}}, {{"plugn", "spatial"}}}}}}}),
            "m.json: pipeline.pair_selector[1]: missing key 'plugin'");
  EXPECT_EQ(ErrorOf({{"pipeline", {{"pair_selector", {{{"plugin", "window"}}, 3}}}}}),
            "m.json: pipeline.pair_selector[1]: expected a JSON object, got a number");
  EXPECT_EQ(ErrorOf({{"pipeline", {{"pair_selectr", {{"plugin", "window"}}}}}}),
            "m.json: pipeline.pair_selectr: unknown key; did you mean 'pair_selector'?");
}

TEST(Manifest, ReadsKFileRelativeToTheManifest) {
  testing::TemporaryDir dir;
  std::ofstream(dir.path() / "K.txt") << "2759.48 0 1520.69\n0 2764.16 1006.81\n0 0 1\n";
  std::ofstream(dir.path() / "m.json") << R"({"camera": {"K_file": "K.txt"}})";
  const Manifest manifest = Manifest::Load(dir.path() / "m.json");
  ASSERT_TRUE(manifest.camera.known_intrinsics);
  EXPECT_DOUBLE_EQ((*manifest.camera.known_intrinsics)(0), 2759.48);
  EXPECT_DOUBLE_EQ((*manifest.camera.known_intrinsics)(3), 1006.81);
  EXPECT_EQ(manifest.camera.known_intrinsics_source, (dir.path() / "K.txt").string());
}

TEST(Manifest, ReportsInvalidJsonWithTheFileAndPosition) {
  testing::TemporaryDir dir;
  std::ofstream(dir.path() / "m.json") << "{\n  \"seed\": 1,\n}\n";
  try {
    Manifest::Load(dir.path() / "m.json");
    FAIL();
  } catch (const InputError& error) {
    const std::string what = error.what();
    EXPECT_EQ(
        what.rfind((dir.path() / "m.json").string() + ": invalid JSON: parse error at line 3", 0),
        0u)
        << what;
  }
  EXPECT_THROW(Manifest::Load(dir.path() / "missing.json"), InputError);
}

// Found by tests/fuzz (manifest target): a number too large for a double is an
// out_of_range error of the JSON parser, not a parse_error; it is invalid JSON all the same.
TEST(Manifest, ReportsANumberOutOfRangeAsInvalidJson) {
  testing::TemporaryDir dir;
  std::ofstream(dir.path() / "m.json") << "{\"seed\": 1E+4440}\n";
  try {
    Manifest::Load(dir.path() / "m.json");
    FAIL();
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              (dir.path() / "m.json").string() +
                  ": invalid JSON at line 1 (key 'seed'): the number '1E+4440' is out of range "
                  "(more than a double can hold)");
  }
}

TEST(Manifest, BadKFileIsAnInputError) {
  testing::TemporaryDir dir;
  std::ofstream(dir.path() / "K.txt") << "1 2 3\n";
  std::ofstream(dir.path() / "m.json") << R"({"camera": {"K_file": "K.txt"}})";
  try {
    Manifest::Load(dir.path() / "m.json");
    FAIL();
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("K.txt: expected 9 numbers (a 3x3 matrix), found 3"),
              std::string::npos)
        << error.what();
  }
}

// A tenth number was ignored, and "nan" reported as "found 0 numbers".
TEST(Manifest, KFileOfOtherThanNineFiniteNumbersNamesTheFileAndTheCulprit) {
  testing::TemporaryDir dir;
  const auto k_file = dir.path() / "K.txt";
  const auto error_of = [&](const std::string& contents) {
    std::ofstream(k_file) << contents;
    try {
      ReadCalibrationMatrixFile(k_file);
    } catch (const InputError& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(error_of("2759.48 0 1520.69\n0 2764.16 1006.81\n0 0 1\n7\n"),
            k_file.string() + ": expected 9 numbers (a 3x3 matrix), found 10");
  EXPECT_EQ(error_of("nan 0 1520.69\n0 2764.16 1006.81\n0 0 1\n"),
            k_file.string() + ": 'nan' is not a finite number (number 1 of the file)");
  EXPECT_EQ(error_of("2759.48 0 1520.69\n0 inf 1006.81\n0 0 1\n"),
            k_file.string() + ": 'inf' is not a finite number (number 5 of the file)");
  EXPECT_EQ(error_of("2759.48 0 1520.69\n0 2764.16 1006.81,\n0 0 1\n"),
            k_file.string() + ": '1006.81,' is not a finite number (number 6 of the file)");
  EXPECT_EQ(error_of("2759.48 0 1520.69\n0 2764.16 1006.81\n0 0 1\n"), "no error");
}

// A BOM (Windows editors) read as part of the first number; a folder as "found 0".
TEST(Manifest, KFileWithABomIsReadAndAFolderIsNamedAsSuch) {
  testing::TemporaryDir dir;
  const auto k_file = dir.path() / "K.txt";
  std::ofstream(k_file) << "\xEF\xBB\xBF"
                        << "574.892 0 316.9\n0 576.1 209.9\n0 0 1\n";
  const Eigen::Matrix3d K = ReadCalibrationMatrixFile(k_file);
  EXPECT_DOUBLE_EQ(K(0, 0), 574.892);
  EXPECT_DOUBLE_EQ(K(1, 2), 209.9);
  try {
    ReadCalibrationMatrixFile(dir.path());
    FAIL() << "a folder was read";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()), dir.path().string() + " is a folder, not a file.");
  }
}

// camera.K and K_file are checked as given: a skew or aspect ratio recorded as a problem,
// a focal length that is not positive refused naming the entry.
TEST(Manifest, AGivenKIsCheckedAsACalibration) {
  testing::TemporaryDir dir;
  std::ofstream(dir.path() / "K.txt") << "2759.48 150 1520.69\n0 2764.16 1006.81\n0 0 1\n";
  std::ofstream(dir.path() / "m.json") << R"({"camera": {"K_file": "K.txt"}})";
  const Manifest manifest = Manifest::Load(dir.path() / "m.json");
  ASSERT_EQ(manifest.camera.known_intrinsics_problems.size(), 1u);
  EXPECT_NE(manifest.camera.known_intrinsics_problems[0].find("K[0][1] (the skew) is 150"),
            std::string::npos);
  std::ofstream(dir.path() / "bad.json") << R"({"camera": {"K": [0, 900, 500, 300]}})";
  try {
    Manifest::Load(dir.path() / "bad.json");
    FAIL() << "fx = 0 was taken";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what())
                  .find("camera.K: fx is 0: focal lengths must be positive finite numbers"),
              std::string::npos)
        << error.what();
  }
}

// A second "pipeline" replaced the first, which then read as "pipeline.detector:
// missing"; any key given twice in one object is refused, named by its path.
TEST(Manifest, ADuplicateKeyIsRefusedNamingItsPathAndTheFile) {
  testing::TemporaryDir dir;
  const auto file = dir.path() / "m.json";
  const auto error_of = [&](const std::string& text) {
    std::ofstream(file) << text;
    try {
      Manifest::Load(file);
    } catch (const InputError& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(error_of(R"({"pipeline": {"detector": {"plugin": "sift"}},
                         "pipeline": {"matcher": {"plugin": "flann"}}})"),
            file.string() + ": pipeline: the key appears twice in one object; give it once");
  EXPECT_EQ(error_of(R"({"pipeline": {"exporters": [{"plugin": "ply"},
                                                    {"plugin": "ply", "plugin": "ply"}]}})"),
            file.string() +
                ": pipeline.exporters[1].plugin: the key appears twice in one object; give it "
                "once");
  EXPECT_EQ(error_of(R"({"plugin_paths": [[], 1, {"a": 1}], "seed": 1, "camera": {"model":
                         "PINHOLE", "K": [1, 1, 0, 0], "K": [2, 2, 0, 0]}})"),
            file.string() + ": camera.K: the key appears twice in one object; give it once");
  // The same key in different objects is fine.
  EXPECT_EQ(error_of(R"({"pipeline": {"detector": {"plugin": "sift"},
                                      "matcher": {"plugin": "flann"}}})"),
            "no error");
}

// The settings a manifest reads by one list (tessera/option_list.h) are checked with it
// where they are used: a value out of its range names the struct and the field.
TEST(Manifest, SettingsChecksNameTheStructAndTheField) {
  EXPECT_NO_THROW(DistributedSettings().Check());
  DistributedSettings distributed;
  distributed.cluster_overlap = 0;
  try {
    distributed.Check();
    ADD_FAILURE() << "cluster_overlap = 0 passed";
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(),
                 "DistributedSettings: cluster_overlap = 0 is out of range [1, 1000000]");
  }
  distributed = DistributedSettings();
  distributed.cluster_max_images = 100;
  EXPECT_THROW(distributed.Check(), InputError);
  EXPECT_EQ(ErrorOf({{"distributed", {{"cluster_overlap", 0}}}}),
            "m.json: distributed.cluster_overlap = 0 is out of range [1, 1000000]");
}

}  // namespace
TEST(Manifest, DistributedClusterSizesDefaultAndAreChecked) {
  const Manifest plain = Manifest::FromJson(nlohmann::json::object(), "/base", "m.json");
  EXPECT_EQ(plain.distributed.cluster_max_images, 300);
  EXPECT_EQ(plain.distributed.cluster_overlap, 40);
  const Manifest small = Manifest::FromJson(
      {{"distributed", {{"cluster_max_images", 30}, {"cluster_overlap", 10}}}}, "/base", "m.json");
  EXPECT_EQ(small.distributed.cluster_max_images, 30);
  EXPECT_EQ(small.distributed.cluster_overlap, 10);
  const std::string too_small =
      ErrorOf({{"distributed", {{"cluster_max_images", 29}, {"cluster_overlap", 10}}}});
  EXPECT_NE(too_small.find("m.json: distributed.cluster_max_images"), std::string::npos)
      << too_small;
  EXPECT_NE(too_small.find("3 times distributed.cluster_overlap (10)"), std::string::npos)
      << too_small;
  EXPECT_NE(ErrorOf({{"distributed", {{"cluster_size", 30}}}}).find("distributed.cluster_size"),
            std::string::npos);
}

// A recipe by name from any folder (`--manifest global`); a path that exists wins; anything
// else is refused with the list of recipes.
TEST(Manifest, FindsABundledRecipeByNameAndAFileThatExistsFirst) {
  testing::TemporaryDir install;
  testing::TemporaryDir work;
  SetExecutableDir(install.path() / "bin");
  const std::filesystem::path recipes = DefaultManifestFile().parent_path();
  std::filesystem::create_directories(recipes);
  std::ofstream(recipes / "global.json") << R"({"seed": 5})";
  std::ofstream(recipes / "fast.json") << R"({"seed": 6})";
  std::ofstream(recipes / "notes.txt") << "not a recipe";
  const std::filesystem::path previous = std::filesystem::current_path();
  std::filesystem::current_path(work.path());
  EXPECT_EQ(BundledRecipeNames(), (std::vector<std::string>{"fast", "global"}));
  EXPECT_EQ(FindManifestFile("global"), recipes / "global.json");
  EXPECT_EQ(FindManifestFile("global.json"), recipes / "global.json");
  EXPECT_EQ(Manifest::Load("global").seed, 5u);
  EXPECT_EQ(Manifest::Load("fast.json").file, recipes / "fast.json");
  std::string refused;
  try {
    FindManifestFile("globl");
  } catch (const InputError& error) {
    refused = error.what();
  }
  EXPECT_EQ(refused,
            "globl: cannot read the manifest: no such file, nor a recipe (the recipes: fast, "
            "global)");
  // A path with a folder is a path: the recipe's name inside it does not count.
  EXPECT_THROW(FindManifestFile("manifests/global.json"), InputError);
  EXPECT_THROW(FindManifestFile("notes"), InputError);
  std::ofstream(work.path() / "global.json") << R"({"seed": 9})";
  EXPECT_EQ(FindManifestFile("global.json"), "global.json");
  EXPECT_EQ(Manifest::Load("global.json").seed, 9u);
  EXPECT_EQ(Manifest::Load("global").seed, 5u);
  std::filesystem::current_path(previous);
  SetExecutableDir("");
}

}  // namespace tessera
