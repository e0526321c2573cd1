#include "pipeline/map_inputs.h"

#include <gtest/gtest.h>

#include "outputs/output_ledger.h"
#include "outputs/output_transaction.h"
#include "tessera/io/file_io.h"
#include "test_support.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

MapInputs ExampleInputs() {
  MapInputs inputs;
  inputs.mapped_at = "2026-12-06 04:51:02 UTC";
  inputs.parts = {{"mapper", "0123456789abcdef"}, {"matches", "fedcba9876543210"}};
  return inputs;
}

// A set as the map stage places it: sparse/0/points3D.bin and mapping_summary.json with
// `inputs`, through an OutputTransaction (so in the ledger).
void PlaceSet(const fs::path& output, const MapInputs& inputs) {
  OutputTransaction outputs(output);
  const fs::path staged = outputs.StageFor("tessera");
  fs::create_directories(staged / "sparse" / "0");
  WriteFileAtomically(staged / "sparse" / "0" / "points3D.bin", "points");
  MappingSummary summary;
  summary.models.emplace_back();
  summary.models[0].folder = (output / "sparse" / "0").string();
  summary.inputs = inputs.ToJson();
  summary.Write(staged / "mapping_summary.json");
  outputs.Commit();
}

TEST(MapInputs, RoundTripsThroughTheMappingSummary) {
  const testing::TemporaryDir dir;
  MappingSummary summary;
  summary.inputs = ExampleInputs().ToJson();
  summary.Write(dir.path() / "mapping_summary.json");
  const MappingSummary back = MappingSummary::Read(dir.path() / "mapping_summary.json");
  const std::optional<MapInputs> inputs = MapInputs::FromJson(back.inputs);
  ASSERT_TRUE(inputs);
  EXPECT_EQ(inputs->parts, ExampleInputs().parts);
  EXPECT_EQ(inputs->mapped_at, "2026-12-06 04:51:02 UTC");
  // A summary without a record (a merge's, an older version's) has none.
  EXPECT_FALSE(MapInputs::FromJson(MappingSummary().inputs));
  EXPECT_FALSE(MapInputs::FromJson({{"parts", {{"mapper", 3}}}}));
}

TEST(MapInputs, TheSameInputsAndAnUnchangedSetKeepTheModels) {
  const testing::TemporaryDir dir;
  PlaceSet(dir.path(), ExampleInputs());
  EXPECT_EQ(ChangedOutputs(dir.path()), "");
  const std::optional<MappingSummary> kept = FindUnchangedModels(dir.path(), ExampleInputs());
  ASSERT_TRUE(kept);
  EXPECT_EQ(kept->models.size(), 1u);
}

TEST(MapInputs, AChangedPartMapsAgain) {
  const testing::TemporaryDir dir;
  PlaceSet(dir.path(), ExampleInputs());
  MapInputs changed = ExampleInputs();
  changed.parts["mapper"] = "0000000000000000";
  EXPECT_FALSE(FindUnchangedModels(dir.path(), changed));
  changed = ExampleInputs();
  changed.parts["rig"] = "0000000000000000";  // a part the record does not have
  EXPECT_FALSE(FindUnchangedModels(dir.path(), changed));
}

TEST(MapInputs, AnEditedOrRemovedModelFileMapsAgain) {
  const testing::TemporaryDir dir;
  PlaceSet(dir.path(), ExampleInputs());
  const fs::path points = dir.path() / "sparse" / "0" / "points3D.bin";
  WriteFileAtomically(points, "pointz");
  EXPECT_EQ(ChangedOutputs(dir.path()), points.string() + " was changed after Tessera wrote it");
  EXPECT_FALSE(FindUnchangedModels(dir.path(), ExampleInputs()));
  fs::remove(points);
  EXPECT_EQ(ChangedOutputs(dir.path()), points.string() + " is missing");
  fs::remove_all(dir.path() / "sparse");
  EXPECT_EQ(ChangedOutputs(dir.path()), points.string() + " is missing");
}

// A set whose placing was stopped: the ledger accepts the old and the new file.
TEST(MapInputs, ASetWhosePlacingWasStoppedMapsAgain) {
  const testing::TemporaryDir dir;
  PlaceSet(dir.path(), ExampleInputs());
  OutputLedger ledger = OutputLedger::Read(dir.path());
  ledger.AddFile("sparse/0/points3D.bin", {3, 42});
  ledger.Write(dir.path());
  EXPECT_NE(ChangedOutputs(dir.path()).find("placing the set was stopped"), std::string::npos);
  EXPECT_FALSE(FindUnchangedModels(dir.path(), ExampleInputs()));
}

// A summary Tessera did not place (not in the ledger) is no record.
TEST(MapInputs, ASummaryNotInTheLedgerMapsAgain) {
  const testing::TemporaryDir dir;
  MappingSummary summary;
  summary.models.emplace_back();
  summary.inputs = ExampleInputs().ToJson();
  summary.Write(dir.path() / "mapping_summary.json");
  EXPECT_EQ(ChangedOutputs(dir.path()),
            (dir.path() / "mapping_summary.json").string() + " is not one Tessera placed");
  EXPECT_FALSE(FindUnchangedModels(dir.path(), ExampleInputs()));
}

}  // namespace
}  // namespace tessera
