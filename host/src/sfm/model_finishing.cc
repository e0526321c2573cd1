#include "tessera/sfm/model_finishing.h"

#include <spdlog/fmt/fmt.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <map>
#include <optional>
#include <set>
#include <utility>

#include "tessera/option_list.h"
#include "tessera/options.h"
#include "util/random.h"

namespace tessera {
namespace {

// Seed stream of each model's GPS anchoring (as the incremental mapper has always drawn it).
constexpr uint64_t kGpsStream = 0x69700;

// The names of the first 10 of `images`, ", ..." after them.
std::string ImageNames(const Reconstruction& model, const std::vector<image_t>& images) {
  std::string names;
  for (size_t i = 0; i < images.size() && i < 10; ++i) {
    names += (i > 0 ? ", " : "") + model.images.at(images[i]).name;
  }
  if (images.size() > 10) names += ", ...";
  return names.empty() ? "none" : names;
}

void LogSelfCheck(const ModelFinishingOptions& options, size_t index, const Reconstruction& model,
                  const ModelSelfCheck& check) {
  if (check.possibly_folded) {
    spdlog::warn(
        "{}: model {} may be folded by symmetric or repeated structure, or joined wrongly: its "
        "poses agree within {:g} deg with {} of its {} verified pairs, which hold only {:.0f}% "
        "of their inliers (min_model_agreement {:.0f}%); images whose pairs mostly disagree: {}",
        options.log_prefix, index, options.max_rotation_error_deg, check.num_agreeing,
        check.num_pairs, 100 * check.agreement, 100 * options.min_model_agreement,
        ImageNames(model, check.disagreeing_images));
  } else {
    spdlog::info(
        "{}: model {}: its poses agree with {} of its {} verified pairs, {:.1f}% of their "
        "inliers",
        options.log_prefix, index, check.num_agreeing, check.num_pairs, 100 * check.agreement);
  }
}

// Model `index` anchored to its images' GPS, logged; its georeference, or nullopt.
std::optional<Georeference> Anchor(const MapperInput& input, const BundleAdjuster& bundle_adjuster,
                                   const ModelFinishingOptions& options, uint64_t seed,
                                   size_t index, Reconstruction* model) {
  const GpsAnchoringReport report = AnchorModelToGps(input.metadata, bundle_adjuster, options.gps,
                                                     DeriveSeed(seed, kGpsStream + index), model);
  for (const GpsTagSetAside& tag : report.set_aside) {
    spdlog::warn("{}: image '{}': its GPS tag {:.7f}, {:.7f}, {} is set aside: {}",
                 options.log_prefix, model->images.at(tag.image_id).name, tag.position.latitude_deg,
                 tag.position.longitude_deg,
                 tag.position.altitude_m ? fmt::format("{:g} m", *tag.position.altitude_m)
                                         : std::string("no altitude"),
                 tag.reason);
  }
  if (!report.anchored) {
    spdlog::warn(
        "{}: model {} is not georeferenced (use_gps_prior): {}; it keeps its own frame and scale",
        options.log_prefix, index, report.reason);
    return std::nullopt;
  }
  spdlog::info(
      "{}: model {}: anchored to the GPS of {} of its {} geotagged images{}, in an "
      "east-north-up frame in metres from {:.7f}, {:.7f}, {:.1f} m (the median of those tags); "
      "camera centres are a mean {:.2f} m (median {:.2f} m) from their GPS positions",
      options.log_prefix, index, report.num_agreeing, report.num_geotagged,
      report.set_aside.empty() ? "" : fmt::format(" ({} tags set aside)", report.set_aside.size()),
      report.origin.latitude_deg, report.origin.longitude_deg, report.origin.altitude_m,
      report.mean_error_m, report.median_error_m);
  return report.origin;
}

}  // namespace

namespace {

// Every field, with its range and its one line of help (tessera/option_list.h): FromJson,
// Check() and Describe() read the same list.
template <typename Options, typename Visitor>
void VisitModelFinishingOptions(Options& o, const Visitor& visit) {
  visit("reg_max_rotation_error", "max_rotation_error_deg", o.max_rotation_error_deg, 0.01, 180.0,
        "degrees: a pair agrees with a model when its relative rotation is the model's within "
        "this");
  visit("min_model_agreement", o.min_model_agreement, 0.0, 1.0,
        "a model whose agreeing pairs hold a smaller share of its pairs' inliers may be folded: "
        "a warning and possibly_folded in mapping_summary.json");
  visit("use_gps_prior", o.use_gps_prior,
        "anchor each model to its images' GPS, in a local east-north-up frame in metres, and "
        "adjust it with every geotagged centre held to its GPS position");
  visit("gps_horizontal_sigma", "gps.horizontal_sigma_m", o.gps.horizontal_sigma_m, 1e-3, 1e6,
        "metres: the GPS positions' horizontal standard deviation, weighting the priors");
  visit("gps_vertical_sigma", "gps.vertical_sigma_m", o.gps.vertical_sigma_m, 1e-3, 1e6,
        "metres: the GPS positions' vertical standard deviation, weighting the priors");
  visit("gps_min_images", "gps.min_num_images", o.gps.min_num_images, 3, 1000000,
        "geotagged images a model needs to be anchored");
}

}  // namespace

ModelFinishingOptions ModelFinishingOptions::FromJson(const nlohmann::json& json,
                                                      const std::string& path) {
  ModelFinishingOptions o;
  OptionReader reader(json, path);
  VisitModelFinishingOptions(o, option_list::Reader(&reader));
  return o;
}

void ModelFinishingOptions::Check() const {
  const option_list::Checker check("ModelFinishingOptions");
  VisitModelFinishingOptions(*this, check);
  check("num_threads", num_threads, 1, 1024);
  check("min_num_matches", min_num_matches, 1, 100000000);
  gps.Check();
}

const std::vector<std::string>& ModelFinishingOptions::JsonKeys() {
  static const std::vector<std::string> keys = {"reg_max_rotation_error", "min_model_agreement",
                                                "use_gps_prior",          "gps_horizontal_sigma",
                                                "gps_vertical_sigma",     "gps_min_images"};
  return keys;
}

nlohmann::json ModelFinishingOptions::Describe() {
  return option_list::DescribeAsJson<ModelFinishingOptions>(
      [](ModelFinishingOptions& o, const auto& visit) { VisitModelFinishingOptions(o, visit); });
}

nlohmann::json ModelFinishingOptions::ToJson() const {
  return {{"reg_max_rotation_error", max_rotation_error_deg},
          {"min_model_agreement", min_model_agreement},
          {"use_gps_prior", use_gps_prior},
          {"gps_horizontal_sigma", gps.horizontal_sigma_m},
          {"gps_vertical_sigma", gps.vertical_sigma_m},
          {"gps_min_images", gps.min_num_images}};
}

bool IsLargerModel(const Reconstruction& a, const Reconstruction& b) {
  if (a.images.size() != b.images.size()) return a.images.size() > b.images.size();
  return a.points3D.size() > b.points3D.size();
}

std::vector<size_t> LargestFirstOrder(const std::vector<Reconstruction>& models) {
  std::vector<size_t> order(models.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return IsLargerModel(models[a], models[b]); });
  return order;
}

void SortModelsLargestFirst(std::vector<Reconstruction>* models) {
  std::stable_sort(models->begin(), models->end(), IsLargerModel);
}

ViewGraph ModelViewGraph(const MapperInput& input, const Reconstruction& model, int min_num_matches,
                         int num_threads, uint64_t seed) {
  std::map<camera_t, Camera> cameras = input.cameras;
  for (const auto& [camera_id, camera] : model.cameras) cameras[camera_id] = camera;
  std::vector<const MapperInput::Pair*> pairs;
  for (const MapperInput::Pair& pair : input.pairs) {
    if (!pair.geometry.inlier_matches.empty() &&
        static_cast<int>(pair.geometry.inlier_matches.size()) >= min_num_matches &&
        model.images.count(pair.image_id1) > 0 && model.images.count(pair.image_id2) > 0) {
      pairs.push_back(&pair);
    }
  }
  return ViewGraph::Build(input, cameras, pairs, seed, num_threads);
}

ModelSelfCheck SelfCheckModel(const ViewGraph& view_graph, const Reconstruction& model,
                              const ModelFinishingOptions& options) {
  const ModelAgreement agreement =
      ComputeModelAgreement(view_graph, model, options.max_rotation_error_deg);
  ModelSelfCheck check;
  check.num_pairs = agreement.num_pairs;
  check.num_agreeing = agreement.num_agreeing;
  check.agreement = agreement.inlier_share;
  for (const auto& image : agreement.disagreeing_images) {
    check.disagreeing_images.push_back(image.image_id);
  }
  check.possibly_folded = agreement.inlier_share < options.min_model_agreement;
  return check;
}

void FinishModels(const MapperInput& input, const BundleAdjuster& bundle_adjuster,
                  const ModelFinishingOptions& options, uint64_t seed, MapperResult* result,
                  const ViewGraph* view_graph) {
  options.Check();
  SortModelsLargestFirst(&result->models);
  result->self_checks.clear();
  for (size_t index = 0; index < result->models.size(); ++index) {
    const Reconstruction& model = result->models[index];
    const ModelSelfCheck check =
        view_graph != nullptr ? SelfCheckModel(*view_graph, model, options)
                              : SelfCheckModel(ModelViewGraph(input, model, options.min_num_matches,
                                                              options.num_threads, seed),
                                               model, options);
    LogSelfCheck(options, index, model, check);
    result->self_checks.push_back(check);
  }
  result->georeferences.clear();
  if (options.use_gps_prior) {
    for (size_t index = 0; index < result->models.size(); ++index) {
      result->georeferences.push_back(
          Anchor(input, bundle_adjuster, options, seed, index, &result->models[index]));
    }
  }
  std::set<image_t> in_model;
  for (const Reconstruction& model : result->models) {
    for (const auto& [image_id, image] : model.images) in_model.insert(image_id);
  }
  for (const image_t image_id : in_model) result->unregistered_reasons.erase(image_id);
  for (const auto& [image_id, image] : input.images) {
    if (in_model.count(image_id) == 0)
      result->unregistered_reasons.emplace(image_id, "in no model");
  }
}

}  // namespace tessera
