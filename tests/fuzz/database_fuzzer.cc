// The database reader: the bytes are a database file. It is opened (which adds missing
// tables) and everything the pipeline reads is read. A file that is not a usable
// Tessera/COLMAP database must be refused with InputError.

#include <algorithm>
#include <filesystem>

#include "database/database.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  namespace fs = std::filesystem;
  const fs::path path = tessera::fuzz::ScratchDir() / "database.db";
  for (const char* suffix : {"", "-journal", "-wal", "-shm"}) {
    std::error_code error;
    fs::remove(path.string() + suffix, error);
  }
  tessera::fuzz::WriteFile(path, std::string_view(reinterpret_cast<const char*>(data), size));
  tessera::fuzz::ExpectReadOrInputError("Database", [&] {
    tessera::Database database(path);
    database.ReadAllCameras();
    database.NumCameras();
    database.NumImages();
    database.NumKeypoints();
    const std::vector<tessera::Image> images = database.ReadAllImages();
    // Bounded, so that a database of many rows still takes milliseconds.
    const size_t num_images = std::min<size_t>(images.size(), 64);
    for (size_t i = 0; i < num_images; ++i) {
      const tessera::image_t image_id = images[i].image_id;
      database.ReadCamera(images[i].camera_id);
      database.ReadImageWithName(images[i].name);
      if (database.ExistsKeypoints(image_id)) database.ReadKeypoints(image_id);
      if (database.ExistsDescriptors(image_id)) {
        database.ReadDescriptors(image_id, tessera::DescriptorMetric::kL2);
      }
    }
    const std::vector<tessera::image_pair_t> pairs = database.ReadMatchedPairIds();
    database.NumMatchedPairs();
    for (size_t i = 0; i < std::min<size_t>(pairs.size(), 64); ++i) {
      const auto [image_id1, image_id2] = tessera::PairIdToImagePair(pairs[i]);
      database.ReadMatches(image_id1, image_id2);
      database.ReadMatches(image_id2, image_id1);
      if (database.ExistsTwoViewGeometry(image_id1, image_id2)) {
        database.ReadTwoViewGeometry(image_id2, image_id1);
      }
    }
    database.ReadAllTwoViewGeometries();
    database.NumVerifiedPairs();
    for (const char* stage :
         {tessera::Database::kFeaturesStage, tessera::Database::kMatchesStage,
          tessera::Database::kTwoViewGeometriesStage, tessera::Database::kImagesStage}) {
      database.ReadStageProvenance(stage);
    }
  });
  return 0;
}
