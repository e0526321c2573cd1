#include "database/matches_table.h"

#include <string>

#include "database/colmap_row_codecs.h"

namespace tessera {
namespace {

std::string MatchesOfImages(image_t image_id1, image_t image_id2) {
  return "the matches of images " + std::to_string(image_id1) + " and " + std::to_string(image_id2);
}

}  // namespace

bool MatchesTable::Exists(image_t image_id1, image_t image_id2) const {
  return exists_.QueryExists(static_cast<int64_t>(ImagePairToPairId(image_id1, image_id2)),
                             "look up " + MatchesOfImages(image_id1, image_id2));
}

void MatchesTable::Write(image_t image_id1, image_t image_id2,
                         const FeatureMatches& matches) const {
  const std::vector<point2D_t> blob = MatchesToBlob(matches, SwapImagePair(image_id1, image_id2));
  SqliteStatement::Use use(write_, "write " + MatchesOfImages(image_id1, image_id2));
  use.BindInt64(1, static_cast<int64_t>(ImagePairToPairId(image_id1, image_id2)));
  use.BindInt64(2, static_cast<int64_t>(matches.size()));
  use.BindInt64(3, 2);
  use.BindBlob(4, blob.data(), sizeof(point2D_t) * blob.size());
  use.Step();
}

FeatureMatches MatchesTable::Read(image_t image_id1, image_t image_id2) const {
  const std::string what = MatchesOfImages(image_id1, image_id2);
  SqliteStatement::Use use(read_, "read " + what);
  use.BindInt64(1, static_cast<int64_t>(ImagePairToPairId(image_id1, image_id2)));
  if (!use.Step()) return {};
  FeatureMatches matches = MatchesFromColumns(use, 0, what);
  return SwapImagePair(image_id1, image_id2) ? SwapMatches(matches) : matches;
}

std::vector<image_pair_t> MatchesTable::ReadPairIds() const {
  SqliteStatement::Use use(read_pair_ids_, "read the matched pairs");
  std::vector<image_pair_t> pair_ids;
  while (use.Step()) pair_ids.push_back(static_cast<image_pair_t>(use.ColumnInt64(0)));
  return pair_ids;
}

size_t MatchesTable::Count() const {
  return static_cast<size_t>(count_.QueryInt64("count the matched pairs"));
}

}  // namespace tessera
