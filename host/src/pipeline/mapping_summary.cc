#include "pipeline/mapping_summary.h"

#include "tessera/errors.h"
#include "tessera/io/file_io.h"

namespace tessera {

nlohmann::json MappingSummary::ToJson() const {
  nlohmann::json json = {{"models", nlohmann::json::array()},
                         {"unregistered", nlohmann::json::array()}};
  for (const Model& model : models) {
    const ViewGraphCheck& check = model.view_graph_check;
    const nlohmann::json self_check = {{"verified_pairs", check.verified_pairs},
                                       {"agreeing_pairs", check.agreeing_pairs},
                                       {"agreement", check.agreement},
                                       {"possibly_folded", check.possibly_folded},
                                       {"disagreeing_images", check.disagreeing_images}};
    json["models"].push_back(
        {{"index", model.index},
         {"folder", model.folder},
         {"num_images", model.num_images},
         {"num_points3D", model.num_points3D},
         {"mean_track_length", model.mean_track_length},
         {"mean_reprojection_error", model.mean_reprojection_error},
         {"mean_observation_reprojection_error", model.mean_observation_reprojection_error},
         {"view_graph_check", self_check},
         {"images", model.images},
         {"georeference", model.georeference},
         {"calibration", model.calibration}});
  }
  for (const Unregistered& image : unregistered) {
    json["unregistered"].push_back({{"image", image.image}, {"reason", image.reason}});
  }
  json["focal_lengths_estimated"] = nlohmann::json::array();
  for (const FocalLength& focal : focal_lengths_estimated) {
    json["focal_lengths_estimated"].push_back({{"camera_id", focal.camera_id},
                                               {"initial", focal.initial},
                                               {"estimated", focal.estimated},
                                               {"method", focal.method},
                                               {"num_pairs", focal.num_pairs},
                                               {"num_images", focal.num_images}});
  }
  json["view_graph_pairs_dropped"] = view_graph_pairs_dropped;
  json["registrations_refused"] = registrations_refused;
  json["merges"] = merges;
  json["quarantined"] = quarantined;
  json["seconds"] = seconds;
  json["mapper"] = mapper;
  json["mapper_options"] = mapper_options;
  json["mapper_details"] = mapper_details;
  json["seed"] = seed;
  if (!rig.is_null()) json["rig"] = rig;
  if (!partition.is_null()) json["partition"] = partition;
  if (!inputs.is_null()) json["inputs"] = inputs;
  return json;
}

MappingSummary MappingSummary::FromJson(const nlohmann::json& json) {
  MappingSummary summary;
  for (const nlohmann::json& entry : json.at("models")) {
    Model model;
    model.index = entry.at("index").get<size_t>();
    model.folder = entry.at("folder").get<std::string>();
    model.num_images = entry.at("num_images").get<size_t>();
    model.num_points3D = entry.at("num_points3D").get<size_t>();
    model.mean_track_length = entry.at("mean_track_length").get<double>();
    model.mean_reprojection_error = entry.at("mean_reprojection_error").get<double>();
    // Absent in summaries written before it had a name of its own.
    model.mean_observation_reprojection_error =
        entry.value("mean_observation_reprojection_error", model.mean_reprojection_error);
    const nlohmann::json& check = entry.at("view_graph_check");
    model.view_graph_check.verified_pairs = check.at("verified_pairs").get<size_t>();
    model.view_graph_check.agreeing_pairs = check.at("agreeing_pairs").get<size_t>();
    model.view_graph_check.agreement = check.at("agreement").get<double>();
    model.view_graph_check.possibly_folded = check.at("possibly_folded").get<bool>();
    model.view_graph_check.disagreeing_images =
        check.at("disagreeing_images").get<std::vector<std::string>>();
    model.images = entry.at("images").get<std::vector<std::string>>();
    // Absent in summaries written before models could be georeferenced.
    model.georeference = entry.value("georeference", nlohmann::json());
    // Absent in summaries written before the calibration was assessed; an object (a
    // type_error otherwise, which Read reports naming the file).
    model.calibration =
        entry.value("calibration", nlohmann::json::object()).get<nlohmann::json::object_t>();
    summary.models.push_back(std::move(model));
  }
  for (const nlohmann::json& entry : json.at("unregistered")) {
    summary.unregistered.push_back(
        {entry.at("image").get<std::string>(), entry.at("reason").get<std::string>()});
  }
  for (const nlohmann::json& entry : json.at("focal_lengths_estimated")) {
    FocalLength focal;
    focal.camera_id = entry.at("camera_id").get<camera_t>();
    focal.initial = entry.at("initial").get<double>();
    focal.estimated = entry.at("estimated").get<double>();
    focal.method = entry.at("method").get<std::string>();
    focal.num_pairs = entry.at("num_pairs").get<size_t>();
    focal.num_images = entry.at("num_images").get<size_t>();
    summary.focal_lengths_estimated.push_back(std::move(focal));
  }
  summary.view_graph_pairs_dropped = json.at("view_graph_pairs_dropped").get<size_t>();
  summary.registrations_refused = json.at("registrations_refused").get<size_t>();
  summary.merges = json.at("merges").get<std::vector<std::string>>();
  // Absent in summaries written before quarantine covered the map stage.
  summary.quarantined =
      json.value("quarantined", nlohmann::json::array()).get<std::vector<std::string>>();
  summary.seconds = json.at("seconds").get<double>();
  // Absent in summaries written before mappers were plugins: the incremental one.
  summary.mapper = json.value("mapper", "incremental");
  summary.mapper_options = json.at("mapper_options");
  summary.mapper_details = json.value("mapper_details", nlohmann::json::object());
  summary.seed = json.at("seed").get<uint64_t>();
  summary.rig = json.value("rig", nlohmann::json());
  summary.partition = json.value("partition", nlohmann::json());
  summary.inputs = json.value("inputs", nlohmann::json());
  return summary;
}

MappingSummary MappingSummary::Read(const std::filesystem::path& file) {
  try {
    return FromJson(nlohmann::json::parse(ReadFileContents(file)));
  } catch (const nlohmann::json::exception& error) {
    throw InputError(file.string() + ": not a mapping summary: " + error.what());
  }
}

void MappingSummary::Write(const std::filesystem::path& file) const {
  WriteFileAtomically(file, ToJson().dump(2) + "\n");
}

}  // namespace tessera
