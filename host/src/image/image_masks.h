#pragma once

// Image masks: one per image, matched by name as COLMAP's `ImageReader.mask_path`
// does. Black (0) mask pixels are ignored: no keypoint is kept there.

#include <filesystem>
#include <map>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "tessera/features.h"

namespace tessera {

// The mask files of a set of images.
struct ImageMasks {
  std::filesystem::path folder;                        // empty: no masks
  std::map<std::string, std::filesystem::path> files;  // image name -> its mask file
  std::vector<std::string> missing;                    // image names without a mask file
  // XXH3-128 over the images' names and their mask files' bytes (32 hex digits), so that
  // features are detected again when a mask changes. Empty without masks.
  std::string digest;
};

// The mask file of image `name` (a path relative to the image folder) in `mask_dir`:
// `mask_dir/NAME.png` as COLMAP (the mask of `a/b.jpg` is `a/b.jpg.png`), else
// `mask_dir/NAME` with its extension replaced by `.png` (`a/b.png`, as nerfstudio
// names them). Empty when neither exists.
std::filesystem::path FindMaskFile(const std::filesystem::path& mask_dir, const std::string& name);

// Finds the mask of each image. Throws InputError naming the folder when it does not exist.
ImageMasks FindImageMasks(const std::filesystem::path& mask_dir,
                          const std::vector<std::string>& image_names);

// Reads a mask as 8-bit grey. Returns nullopt with `problem` set (a sentence that does
// not name the image) when the file cannot be decoded or is not `width` x `height`.
std::optional<cv::Mat> ReadMask(const std::filesystem::path& file, int width, int height,
                                std::string* problem);

// Removes the keypoints, and their descriptors, that lie on a black (0) pixel of
// `mask` (the pixel holding the keypoint's position; positions outside the mask are
// clamped to its border). Returns the number removed.
size_t RemoveMaskedFeatures(const cv::Mat& mask, FeatureSet* features);

}  // namespace tessera
