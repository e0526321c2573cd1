#pragma once

// A workspace and a folder of small noise images for the import tests, and features
// for them made up in memory.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <string>
#include <vector>

#include "pipeline/workspace.h"
#include "toolbox/feature_import.h"

namespace tessera::testing {

inline void WriteText(const std::filesystem::path& file, const std::string& text) {
  std::filesystem::create_directories(file.parent_path());
  std::ofstream(file, std::ios::binary) << text;
}

// `call` throws an InputError whose message contains `expected`.
inline void ExpectInputError(const std::function<void()>& call, const std::string& expected) {
  try {
    call();
    ADD_FAILURE() << "no InputError; expected one containing: " << expected;
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find(expected), std::string::npos)
        << "message: " << error.what() << "\nexpected in it: " << expected;
  }
}

struct ImportFixture {
  static constexpr size_t kNumKeypoints = 20;
  static constexpr int kWidth = 80, kHeight = 60;

  // `num_images` noise images ROOT/images/I.png and the workspace ROOT/ws.
  ImportFixture(const std::filesystem::path& root, int num_images) : images(root / "images") {
    std::filesystem::create_directories(images);
    for (int i = 0; i < num_images; ++i) {
      cv::Mat image(kHeight, kWidth, CV_8UC1);
      cv::randu(image, i, 256);
      cv::imwrite((images / (std::to_string(i) + ".png")).string(), image);
      names.push_back(std::to_string(i) + ".png");
    }
    workspace = Workspace::Open(root / "ws");
  }

  // The same made-up features on every call: kNumKeypoints per image inside it,
  // normally distributed descriptor values of `dimension`.
  std::vector<ImportedFeatures> Features(int dimension) const {
    std::vector<ImportedFeatures> features;
    for (size_t i = 0; i < names.size(); ++i) {
      ImportedFeatures image;
      image.name = names[i];
      image.source = "features['" + names[i] + "']";
      std::mt19937 random(static_cast<unsigned>(i));
      std::normal_distribution<float> normal;
      for (size_t k = 0; k < kNumKeypoints; ++k) {
        image.keypoints.emplace_back(3.5f * k + 2, 2.5f * k + static_cast<float>(i) + 1);
      }
      image.descriptors.resize(kNumKeypoints, dimension);
      for (Eigen::Index v = 0; v < image.descriptors.size(); ++v) {
        image.descriptors.data()[v] = normal(random);
      }
      features.push_back(std::move(image));
    }
    return features;
  }

  FeatureImportSummary Import(std::vector<ImportedFeatures> features) const {
    FeatureImportSettings settings;
    settings.image_dir = images;
    return ImportFeatures(*workspace, settings, FeatureMemorySource(std::move(features)));
  }

  std::filesystem::path images;
  std::vector<std::string> names;
  std::unique_ptr<Workspace> workspace;
};

}  // namespace tessera::testing
