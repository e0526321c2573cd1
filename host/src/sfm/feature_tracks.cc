#include "tessera/sfm/feature_tracks.h"

#include <algorithm>
#include <numeric>
#include <string>

#include "tessera/errors.h"

namespace tessera {
namespace {

// Union-find over all features of all images, with the set of images each root's set
// covers, so that a union that would put two features of one image together is seen
// in O(images in the two sets).
class ConsistentUnionFind {
 public:
  explicit ConsistentUnionFind(std::vector<image_t> image_of_node)
      : image_of_node_(std::move(image_of_node)),
        parent_(image_of_node_.size()),
        images_(image_of_node_.size()) {
    std::iota(parent_.begin(), parent_.end(), 0);
  }

  size_t Find(size_t node) {
    while (parent_[node] != node) {
      parent_[node] = parent_[parent_[node]];  // path halving
      node = parent_[node];
    }
    return node;
  }

  // Joins the sets of a and b unless they share an image; false when refused.
  bool Union(size_t a, size_t b) {
    size_t root_a = Find(a);
    size_t root_b = Find(b);
    if (root_a == root_b) return true;
    const std::vector<image_t> images_a = ImagesOf(root_a);
    const std::vector<image_t> images_b = ImagesOf(root_b);
    std::vector<image_t> joined;
    joined.reserve(images_a.size() + images_b.size());
    std::merge(images_a.begin(), images_a.end(), images_b.begin(), images_b.end(),
               std::back_inserter(joined));
    if (std::adjacent_find(joined.begin(), joined.end()) != joined.end()) return false;
    // The smaller root index becomes the root, which keeps the result order-free.
    if (root_b < root_a) std::swap(root_a, root_b);
    parent_[root_b] = root_a;
    images_[root_a] = std::move(joined);
    images_[root_b].clear();
    images_[root_b].shrink_to_fit();
    return true;
  }

 private:
  std::vector<image_t> ImagesOf(size_t root) const {
    if (images_[root].empty()) return {image_of_node_[root]};  // a single feature
    return images_[root];
  }

  std::vector<image_t> image_of_node_;
  std::vector<size_t> parent_;
  std::vector<std::vector<image_t>> images_;  // sorted; empty for singletons and non-roots
};

}  // namespace

track_t FeatureTracks::TrackOf(image_t image_id, point2D_t point2D_idx) const {
  const auto it = track_of_feature.find(image_id);
  if (it == track_of_feature.end() || point2D_idx >= it->second.size()) return kInvalidTrackId;
  return it->second[point2D_idx];
}

void FeatureTracks::Merge(track_t into, track_t from) {
  if (into == from) return;
  Track& target = tracks.at(into);
  for (const TrackElement& element : tracks.at(from)) {
    track_of_feature.at(element.image_id).at(element.point2D_idx) = into;
    target.push_back(element);
  }
  std::sort(target.begin(), target.end(), [](const TrackElement& a, const TrackElement& b) {
    return a.image_id != b.image_id ? a.image_id < b.image_id : a.point2D_idx < b.point2D_idx;
  });
  tracks[from].clear();
}

FeatureTracks BuildFeatureTracks(const std::vector<ImagePairMatches>& pairs,
                                 const std::map<image_t, size_t>& num_points2D) {
  // Node index of feature (image, idx) = offset[image] + idx.
  std::map<image_t, size_t> offset;
  std::vector<image_t> image_of_node;
  for (const auto& [image_id, count] : num_points2D) {
    offset[image_id] = image_of_node.size();
    image_of_node.insert(image_of_node.end(), count, image_id);
  }
  const auto node_of = [&](image_t image_id, point2D_t idx, const ImagePairMatches& pair) {
    const auto it = offset.find(image_id);
    if (it == offset.end() || idx >= num_points2D.at(image_id)) {
      throw InputError("matches of images " + std::to_string(pair.image_id1) + " and " +
                       std::to_string(pair.image_id2) + " refer to keypoint " +
                       std::to_string(idx) + " of image " + std::to_string(image_id) +
                       ", which does not exist");
    }
    return it->second + idx;
  };

  std::vector<const ImagePairMatches*> order;
  for (const ImagePairMatches& pair : pairs) order.push_back(&pair);
  std::sort(order.begin(), order.end(), [](const ImagePairMatches* a, const ImagePairMatches* b) {
    if (a->matches.size() != b->matches.size()) return a->matches.size() > b->matches.size();
    if (a->image_id1 != b->image_id1) return a->image_id1 < b->image_id1;
    return a->image_id2 < b->image_id2;
  });

  ConsistentUnionFind union_find(image_of_node);
  std::vector<std::pair<size_t, size_t>> refused;
  for (const ImagePairMatches* pair : order) {
    for (const FeatureMatch& match : pair->matches) {
      const size_t node1 = node_of(pair->image_id1, match.point2D_idx1, *pair);
      const size_t node2 = node_of(pair->image_id2, match.point2D_idx2, *pair);
      if (pair->image_id1 == pair->image_id2 || !union_find.Union(node1, node2)) {
        refused.emplace_back(node1, node2);
      }
    }
  }

  FeatureTracks result;
  result.num_refused_matches = refused.size();
  // Sets of two or more features become tracks, numbered by their smallest feature.
  std::vector<size_t> size_of_root(image_of_node.size(), 0);
  for (size_t node = 0; node < image_of_node.size(); ++node) ++size_of_root[union_find.Find(node)];
  std::vector<track_t> track_of_root(image_of_node.size(), kInvalidTrackId);
  for (const auto& [image_id, count] : num_points2D) {
    result.track_of_feature[image_id].assign(count, kInvalidTrackId);
  }
  for (size_t node = 0; node < image_of_node.size(); ++node) {
    const size_t root = union_find.Find(node);
    if (size_of_root[root] < 2) continue;
    if (track_of_root[root] == kInvalidTrackId) {
      track_of_root[root] = static_cast<track_t>(result.tracks.size());
      result.tracks.emplace_back();
    }
    const image_t image_id = image_of_node[node];
    const point2D_t idx = static_cast<point2D_t>(node - offset.at(image_id));
    result.tracks[track_of_root[root]].push_back({image_id, idx});
    result.track_of_feature[image_id][idx] = track_of_root[root];
  }
  for (const auto& [node1, node2] : refused) {
    const track_t track1 = track_of_root[union_find.Find(node1)];
    const track_t track2 = track_of_root[union_find.Find(node2)];
    if (track1 == kInvalidTrackId || track2 == kInvalidTrackId || track1 == track2) continue;
    result.refused_links.emplace_back(std::min(track1, track2), std::max(track1, track2));
  }
  std::sort(result.refused_links.begin(), result.refused_links.end());
  result.refused_links.erase(std::unique(result.refused_links.begin(), result.refused_links.end()),
                             result.refused_links.end());
  return result;
}

}  // namespace tessera
