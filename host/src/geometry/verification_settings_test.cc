#include "geometry/verification_settings.h"

#include <gtest/gtest.h>

#include <vector>

#include "tessera/errors.h"

namespace tessera {
namespace {

TEST(VerificationSettings, ToJsonHasEveryFieldByItsManifestKey) {
  const nlohmann::json json = VerificationSettings().ToJson();
  EXPECT_EQ(json.size(), 7u);
  EXPECT_DOUBLE_EQ(json.at("max_error_px").get<double>(), 4.0);
  EXPECT_DOUBLE_EQ(json.at("confidence").get<double>(), 0.999);
  EXPECT_EQ(json.at("min_num_trials").get<int>(), 100);
  EXPECT_EQ(json.at("max_num_trials").get<int>(), 10000);
  EXPECT_DOUBLE_EQ(json.at("min_inlier_ratio").get<double>(), 0.25);
  EXPECT_EQ(json.at("min_num_inliers").get<int>(), 15);
  EXPECT_DOUBLE_EQ(json.at("max_H_inlier_ratio").get<double>(), 0.8);
}

TEST(VerificationSettings, EveryFieldChangesTheJson) {
  const nlohmann::json defaults = VerificationSettings().ToJson();
  std::vector<VerificationSettings> changed(7);
  changed[0].max_error_px = 2;
  changed[1].confidence = 0.99;
  changed[2].min_num_trials = 50;
  changed[3].max_num_trials = 500;
  changed[4].min_inlier_ratio = 0.1;
  changed[5].min_num_inliers = 30;
  changed[6].max_H_inlier_ratio = 0.7;
  for (const VerificationSettings& settings : changed) EXPECT_NE(settings.ToJson(), defaults);
}

// Check() refuses a field out of the range the manifest reads it with, naming the struct
// and the field, and min_num_trials above max_num_trials.
TEST(VerificationSettings, CheckNamesTheStructAndTheField) {
  EXPECT_NO_THROW(VerificationSettings().Check());
  VerificationSettings settings;
  settings.confidence = 1;
  try {
    settings.Check();
    ADD_FAILURE() << "confidence = 1 passed";
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(),
                 "VerificationSettings: confidence = 1 is out of range [0.5, 0.999999]");
  }
  settings = VerificationSettings();
  settings.min_num_trials = 20000;
  EXPECT_THROW(settings.Check(), InputError);
}

}  // namespace
}  // namespace tessera
