#pragma once

// The plugin ABI. Every plugin is a shared object exporting, through Boost.DLL
// aliases, two symbols:
//   tessera_plugin_info    -> const TesseraPluginInfo  (what the plugin is)
//   tessera_plugin_create  -> tessera::PluginFactory   (makes it from JSON options)
// TESSERA_PLUGIN() below defines both. Host and plugins must be built with the same
// compiler and standard library, since C++ objects cross the boundary.

#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "tessera/export.h"

// Bumped whenever TesseraPluginInfo, a plugin interface, a type that crosses the
// boundary or the API of Tessera::io (tessera/io/) changes; the host refuses a plugin
// built against another version. libtessera_io's SONAME carries this number
// (libtessera_io.so.4), so a plugin linked against another Tessera::io does not load.
// abi_headers.sha256 records it with a hash of every header here, comments and whitespace
// excluded: the test sdk_abi_check fails when a header changes without a bump (bump it,
// then run scripts/sdk_abi_check.py --update).
#define TESSERA_PLUGIN_ABI_VERSION 4

extern "C" {
// The info record. `abi_version` stays the first member in every version so that
// any host can read it.
struct TesseraPluginInfo {
  uint32_t abi_version;
  const char* kind;  // "detector", "matcher", "pair_selector", "bundle_adjuster", "exporter"
  const char* name;
  const char* version;
  const char* description;
};
}

namespace tessera {

constexpr uint32_t kPluginAbiVersion = TESSERA_PLUGIN_ABI_VERSION;

// Base of every plugin object.
class TESSERA_API Plugin {
 public:
  virtual ~Plugin() = default;

  // The options in effect, defaults filled in. The host records them with the
  // results this plugin produced, so that a change invalidates those results.
  const nlohmann::json& EffectiveOptions() const { return effective_options_; }

 protected:
  nlohmann::json effective_options_ = nlohmann::json::object();
};

// Makes a plugin from its options. Throws tessera::OptionError for invalid options.
using PluginFactory = std::unique_ptr<Plugin>(const nlohmann::json& options);

}  // namespace tessera

// Defines the info record and the factory of a plugin. KIND is one of detector,
// matcher, pair_selector, bundle_adjuster, exporter; CLASS derives from that kind's
// interface and has a constructor taking `const nlohmann::json& options`.
//
//   TESSERA_PLUGIN(detector, SiftDetector, "sift", "1.0.0", "SIFT (OpenCV)")
#define TESSERA_PLUGIN(KIND, CLASS, NAME, VERSION, DESCRIPTION)                                  \
  static_assert(std::is_base_of_v<::tessera::plugin_kinds::KIND, CLASS>,                         \
                #CLASS " must derive from the " #KIND " interface");                             \
  extern "C" {                                                                                   \
  const TesseraPluginInfo tessera_plugin_info_record = {TESSERA_PLUGIN_ABI_VERSION, #KIND, NAME, \
                                                        VERSION, DESCRIPTION};                   \
  }                                                                                              \
  static std::unique_ptr<::tessera::Plugin> tessera_plugin_create_impl(                          \
      const nlohmann::json& options) {                                                           \
    return std::make_unique<CLASS>(options);                                                     \
  }                                                                                              \
  BOOST_DLL_ALIAS(tessera_plugin_info_record, tessera_plugin_info)                               \
  BOOST_DLL_ALIAS(tessera_plugin_create_impl, tessera_plugin_create)
