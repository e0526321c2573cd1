#pragma once

// JSON between the host (nlohmann::json) and Python (dicts, lists, numbers), through
// Python's json module: the host's summaries become dicts, a manifest dict the host's
// JSON, with the same numbers the files would hold.

#include <pybind11/pybind11.h>

#include <nlohmann/json.hpp>
#include <string>

namespace tessera::python {

inline nlohmann::json ToJson(const pybind11::handle& object) {
  return nlohmann::json::parse(
      pybind11::module_::import("json").attr("dumps")(object).cast<std::string>());
}

inline pybind11::object ToPython(const nlohmann::json& json) {
  return pybind11::module_::import("json").attr("loads")(json.dump());
}

}  // namespace tessera::python
