#include "pipeline/run_summary.h"

namespace tessera {

void to_json(nlohmann::json& json, const SelectorPairs& pairs) {
  json = {{"plugin", pairs.plugin}, {"json_path", pairs.json_path}, {"num_pairs", pairs.num_pairs}};
}

void from_json(const nlohmann::json& json, SelectorPairs& pairs) {
  pairs.plugin = json.at("plugin").get<std::string>();
  pairs.json_path = json.at("json_path").get<std::string>();
  pairs.num_pairs = json.at("num_pairs").get<size_t>();
}

void to_json(nlohmann::json& json, const PluginUsed& plugin) {
  json = {{"slot", plugin.slot},
          {"plugin", plugin.plugin},
          {"version", plugin.version},
          {"file", plugin.file},
          {"file_hash", plugin.file_hash}};
}

void from_json(const nlohmann::json& json, PluginUsed& plugin) {
  plugin.slot = json.at("slot").get<std::string>();
  plugin.plugin = json.at("plugin").get<std::string>();
  plugin.version = json.at("version").get<std::string>();
  plugin.file = json.value("file", "");
  plugin.file_hash = json.value("file_hash", "");
}

nlohmann::json RunSummary::ToJson() const {
  nlohmann::json selectors = nlohmann::json::array();
  for (const SelectorPairs& selector : match.pairs_per_selector) selectors.push_back(selector);
  return {{"extract",
           {{"seconds", extract.seconds},
            {"num_images", extract.num_images},
            {"num_detected", extract.num_detected},
            {"num_reused", extract.num_reused},
            {"num_failed", extract.num_failed},
            {"num_quarantined", extract.num_quarantined},
            {"num_changed", extract.num_changed},
            {"num_removed", extract.num_removed}}},
          {"match",
           {{"seconds", match.seconds},
            {"num_pairs", match.num_pairs},
            {"pairs_per_selector", selectors},
            {"num_matched", match.num_matched},
            {"num_reused", match.num_reused},
            {"num_quarantined", match.num_quarantined},
            {"num_verified", match.num_verified}}},
          {"map",
           {{"seconds", map.seconds},
            {"num_models", map.num_models},
            {"num_registered", map.num_registered},
            {"num_images", map.num_images},
            {"images_per_model", map.images_per_model},
            {"kept", map.kept}}},
          {"total_seconds", total_seconds},
          {"plugins", plugins}};
}

RunSummary RunSummary::FromJson(const nlohmann::json& json) {
  RunSummary summary;
  const nlohmann::json& extract = json.at("extract");
  summary.extract.seconds = extract.at("seconds").get<double>();
  summary.extract.num_images = extract.at("num_images").get<size_t>();
  summary.extract.num_detected = extract.at("num_detected").get<size_t>();
  summary.extract.num_reused = extract.at("num_reused").get<size_t>();
  summary.extract.num_failed = extract.at("num_failed").get<size_t>();
  summary.extract.num_quarantined = extract.value("num_quarantined", size_t{0});  // older files
  summary.extract.num_changed = extract.at("num_changed").get<size_t>();
  summary.extract.num_removed = extract.at("num_removed").get<size_t>();
  const nlohmann::json& match = json.at("match");
  summary.match.seconds = match.at("seconds").get<double>();
  summary.match.num_pairs = match.at("num_pairs").get<size_t>();
  for (const nlohmann::json& selector :
       match.value("pairs_per_selector", nlohmann::json::array())) {
    summary.match.pairs_per_selector.push_back(selector.get<SelectorPairs>());
  }
  summary.match.num_matched = match.at("num_matched").get<size_t>();
  summary.match.num_reused = match.at("num_reused").get<size_t>();
  summary.match.num_quarantined = match.value("num_quarantined", size_t{0});
  summary.match.num_verified = match.at("num_verified").get<size_t>();
  const nlohmann::json& map = json.at("map");
  summary.map.seconds = map.at("seconds").get<double>();
  summary.map.num_models = map.at("num_models").get<size_t>();
  summary.map.num_registered = map.at("num_registered").get<size_t>();
  summary.map.num_images = map.at("num_images").get<size_t>();
  summary.map.images_per_model =
      map.value("images_per_model", nlohmann::json::array()).get<std::vector<size_t>>();
  summary.map.kept = map.value("kept", false);
  summary.total_seconds = json.at("total_seconds").get<double>();
  summary.plugins = json.value("plugins", nlohmann::json::array()).get<std::vector<PluginUsed>>();
  return summary;
}

}  // namespace tessera
