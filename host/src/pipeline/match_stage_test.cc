#include "pipeline/match_stage.h"

#include <gtest/gtest.h>

#include <set>

#include "pipeline/extract_stage.h"
#include "pipeline/load_mapper_input.h"
#include "pipeline/stage_test_util.h"

namespace tessera {
namespace {

// A workspace of 4 images (6 pairs) with features.
class MatchStageTest : public ::testing::Test {
 protected:
  void SetUp() override {
    testing::WriteSampleImages(dir_.path() / "images", 4);
    workspace_ = Workspace::Open(dir_.path());
    database_ = &workspace_->database();
    ExtractFeatures(*workspace_,
                    plugins_.Extract(dir_.path() / "images", testing::CheapManifest(2)));
  }
  MatchingSummary Match(const Manifest& manifest, const StageControl& control = {}) {
    return MatchFeatures(*workspace_, plugins_.Match(manifest), {}, control);
  }

  testing::TemporaryDir dir_;
  testing::CheapPlugins plugins_;
  std::unique_ptr<Workspace> workspace_;
  Database* database_ = nullptr;
};

TEST_F(MatchStageTest, CancelledAfterThreePairsKeepsThemAndARerunDoesTheRest) {
  CancellationToken token;
  StageControl control;
  control.cancel = &token;
  control.progress = [&](const std::string&, size_t done, size_t) {
    if (done == 3) token.Cancel();
  };
  const MatchingSummary first = Match(testing::CheapManifest(1), control);
  EXPECT_EQ(first.status, StageStatus::kCancelled);
  EXPECT_EQ(first.num_pairs, 6u);
  EXPECT_EQ(first.num_matched, 3u);
  EXPECT_EQ(database_->NumMatchedPairs(), 3u);
  EXPECT_EQ(database_->ReadAllTwoViewGeometries().size(), 3u);

  const MatchingSummary second = Match(testing::CheapManifest(1));
  EXPECT_EQ(second.status, StageStatus::kCompleted);
  EXPECT_EQ(second.num_reused, 3u);
  EXPECT_EQ(second.num_matched, 3u);
  EXPECT_EQ(database_->NumMatchedPairs(), 6u);
  EXPECT_EQ(database_->ReadAllTwoViewGeometries().size(), 6u);
}

TEST_F(MatchStageTest, ProgressIsMonotoneAndEndsAtTotal) {
  std::vector<std::pair<size_t, size_t>> calls;
  StageControl control;
  control.progress = [&](const std::string& stage, size_t done, size_t total) {
    EXPECT_EQ(stage, "match");
    calls.emplace_back(done, total);
  };
  EXPECT_EQ(Match(testing::CheapManifest(3), control).status, StageStatus::kCompleted);
  ASSERT_EQ(calls.size(), 6u);
  for (size_t k = 0; k < calls.size(); ++k) {
    EXPECT_EQ(calls[k].first, k + 1);
    EXPECT_EQ(calls[k].second, 6u);
  }
}

TEST_F(MatchStageTest, TheThreeStepsOneByOne) {
  const MatchSettings settings = plugins_.Match(testing::CheapManifest(1));
  const WorkspaceDescriptors descriptors = ReadWorkspaceDescriptors(*database_);
  EXPECT_EQ(descriptors.metric, DescriptorMetric::kHamming);
  EXPECT_EQ(descriptors.dimension, 32);  // ORB: 256 bits
  InvalidateStaleResults(settings, descriptors, database_);
  const MatchProvenance provenance = MakeMatchProvenance(settings, descriptors);
  const MatchPlan plan = PlanMatching(*workspace_, settings, descriptors, provenance);
  ASSERT_EQ(plan.images.size(), 4u);
  EXPECT_EQ(plan.images.front().name, "0000.jpg");
  EXPECT_EQ(plan.pairs.size(), 6u);
  EXPECT_EQ(plan.todo.size(), 6u);
  ASSERT_EQ(plan.pairs_per_selector.size(), 1u);
  EXPECT_EQ(plan.pairs_per_selector[0].num_pairs, 6u);

  // Neighbouring views of the fountain: many putative matches, a verified geometry.
  PairMatchVerifier verifier(settings, plan, descriptors, database_, database_);
  const PairResult result = verifier.Run(plan.todo.front());
  EXPECT_GT(result.num_putative_matches, 100u);
  EXPECT_GE(result.num_inlier_matches, 15u);
  EXPECT_LE(result.num_inlier_matches, result.num_putative_matches);
  EXPECT_EQ(database_->NumMatchedPairs(), 1u);

  const MatchPlan again = PlanMatching(*workspace_, settings, descriptors, provenance);
  EXPECT_EQ(again.num_reused, 1u);
  EXPECT_EQ(again.todo.size(), 5u);
}

// Staleness comes from VerificationSettings::ToJson: changing any field it has (set
// through the manifest, by its key) recomputes every geometry; the same settings reuse.
TEST_F(MatchStageTest, AnyChangedVerificationFieldRecomputesTheGeometries) {
  EXPECT_EQ(Match(testing::CheapManifest(2)).num_matched, 6u);
  EXPECT_EQ(Match(testing::CheapManifest(2)).num_reused, 6u);
  const nlohmann::json defaults = VerificationSettings().ToJson();
  ASSERT_EQ(defaults.size(), 7u);
  for (const auto& [key, value] : defaults.items()) {
    nlohmann::json changed = nlohmann::json::object();
    changed[key] = value.is_number_integer() ? nlohmann::json(value.get<int>() + 1)
                                             : nlohmann::json(value.get<double>() * 0.9);
    const Manifest manifest = testing::CheapManifest(2, changed);
    ASSERT_NE(manifest.verification.ToJson(), defaults) << key;
    const MatchingSummary summary = Match(manifest);
    EXPECT_EQ(summary.num_reused, 0u) << key;
    EXPECT_EQ(summary.num_matched, 6u) << key;
    // Back to the defaults: recomputed again, then reused.
    EXPECT_EQ(Match(testing::CheapManifest(2)).num_reused, 0u) << key;
  }
  EXPECT_EQ(Match(testing::CheapManifest(2)).num_reused, 6u);
}

// Exhaustive, then `window` 1: mapping uses the three neighbouring pairs only, while
// the others stay cached, so that going back to exhaustive matches nothing again.
TEST_F(MatchStageTest, MappingUsesOnlyThePairsTheCurrentSelectionChose) {
  EXPECT_EQ(Match(testing::CheapManifest(2)).num_matched, 6u);
  std::map<image_t, int> index;  // 0000.jpg is 0
  for (const Image& image : database_->ReadAllImages())
    index[image.image_id] = std::stoi(image.name);
  const auto mapped_gaps = [&] {  // the index distance of each pair mapping gets
    std::multiset<int> gaps;
    for (const MapperInput::Pair& pair : LoadMapperInput(*database_).pairs) {
      gaps.insert(std::abs(index.at(pair.image_id1) - index.at(pair.image_id2)));
    }
    return gaps;
  };
  const std::multiset<int> exhaustive = mapped_gaps();
  ASSERT_GT(exhaustive.count(2) + exhaustive.count(3), 0u) << "no pair beyond neighbours verified";

  std::vector<PluginInstance<PairSelector>> window;
  window.push_back(testing::LoadBundledPlugin<PairSelector>(
      "pair_selector", "window", {{"window", 1}}, "pipeline.pair_selector"));
  MatchSettings settings = plugins_.Match(testing::CheapManifest(2));
  settings.pair_selectors = &window;
  const MatchingSummary windowed = MatchFeatures(*workspace_, settings);
  EXPECT_EQ(windowed.num_pairs, 3u);
  EXPECT_EQ(windowed.num_reused, 3u);
  EXPECT_EQ(windowed.num_matched, 0u);
  EXPECT_EQ(mapped_gaps(),
            std::multiset<int>(exhaustive.lower_bound(1), exhaustive.upper_bound(1)));
  EXPECT_EQ(database_->NumMatchedPairs(), 6u);  // the others stay cached
  EXPECT_EQ(database_->ReadAllTwoViewGeometries().size(), 6u);
  EXPECT_EQ(database_->ReadSelectedPairs()->size(), 3u);

  const MatchingSummary again = Match(testing::CheapManifest(2));
  EXPECT_EQ(again.num_reused, 6u);
  EXPECT_EQ(again.num_matched, 0u);
  EXPECT_EQ(mapped_gaps(), exhaustive);
}

}  // namespace
}  // namespace tessera
