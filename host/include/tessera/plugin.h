#pragma once

// The plugin ABI. Every plugin is a shared object exporting, through Boost.DLL
// aliases, two symbols:
//   tessera_plugin_info    -> const TesseraPluginInfo  (what the plugin is)
//   tessera_plugin_create  -> tessera::PluginFactory   (makes it from JSON options and
//                                                       the host's services)
// TESSERA_PLUGIN() below defines both. A third, which every bundled plugin exports:
//   tessera_plugin_options -> tessera::PluginOptionsDescriber (its options described:
//                                                       `tessera plugins NAME`)
// TESSERA_PLUGIN_OPTIONS() defines it; a plugin without it is listed as not describing
// its options. Host and plugins must be built with the same
// compiler and standard library, since C++ objects cross the boundary.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tessera/export.h"
#include "tessera/log.h"
#include "tessera/option_list.h"
#include "tessera/plugin_services.h"

// Bumped whenever TesseraPluginInfo, a plugin interface, a type that crosses the
// boundary or the API of Tessera::io (tessera/io/) changes; the host refuses a plugin
// built against another version. libtessera_io's SONAME carries this number
// (libtessera_io.so.N), so a plugin linked against another Tessera::io does not load.
// abi_headers.sha256 records it with a hash of every header here, comments and whitespace
// excluded: the test sdk_abi_check fails when a header changes without a bump (bump it,
// then run scripts/sdk_abi_check.py --update).
#define TESSERA_PLUGIN_ABI_VERSION 12

extern "C" {
// How a binary was built, as far as the C++ objects that cross the plugin boundary
// depend on it. The host refuses a plugin whose record differs from its own, naming the
// setting (a plugin built with -D_GLIBCXX_USE_CXX11_ABI=0 would otherwise load and then
// fail with std::bad_alloc on its first std::string).
struct TesseraBuildRecord {
  uint32_t compiler;          // 1 GCC, 2 Clang, 0 another
  uint32_t compiler_major;    // __GNUC__ or __clang_major__
  uint32_t standard_library;  // 1 libstdc++, 2 libc++, 0 another
  uint32_t string_abi;        // libstdc++'s _GLIBCXX_USE_CXX11_ABI (1 or 0); 0 for others
  uint32_t sizeof_string;     // sizeof(std::string)
  uint32_t sizeof_vector;     // sizeof(std::vector<int>)
  uint32_t sizeof_function;   // sizeof(std::function<void()>)
  uint32_t sizeof_json;       // sizeof(nlohmann::json)
  uint32_t sizeof_path;       // sizeof(std::filesystem::path)
};

// The info record. `abi_version` stays the first member in every version so that
// any host can read it.
struct TesseraPluginInfo {
  uint32_t abi_version;
  const char* kind;  // "detector", "matcher", "pair_selector", "mapper", "bundle_adjuster",
                     // "exporter"
  const char* name;
  const char* version;
  const char* description;
  TesseraBuildRecord build;  // TESSERA_BUILD_RECORD where the plugin was compiled
};
}

#if defined(__clang__)
#define TESSERA_BUILD_COMPILER 2u, static_cast<uint32_t>(__clang_major__)
#elif defined(__GNUC__)
#define TESSERA_BUILD_COMPILER 1u, static_cast<uint32_t>(__GNUC__)
#else
#define TESSERA_BUILD_COMPILER 0u, 0u
#endif
#if defined(__GLIBCXX__)
#define TESSERA_BUILD_STANDARD_LIBRARY 1u, static_cast<uint32_t>(_GLIBCXX_USE_CXX11_ABI)
#elif defined(_LIBCPP_VERSION)
#define TESSERA_BUILD_STANDARD_LIBRARY 2u, 0u
#else
#define TESSERA_BUILD_STANDARD_LIBRARY 0u, 0u
#endif
// The build record of the translation unit that expands it.
#define TESSERA_BUILD_RECORD                                  \
  TesseraBuildRecord {                                        \
    TESSERA_BUILD_COMPILER, TESSERA_BUILD_STANDARD_LIBRARY,   \
        static_cast<uint32_t>(sizeof(std::string)),           \
        static_cast<uint32_t>(sizeof(std::vector<int>)),      \
        static_cast<uint32_t>(sizeof(std::function<void()>)), \
        static_cast<uint32_t>(sizeof(nlohmann::json)),        \
        static_cast<uint32_t>(sizeof(std::filesystem::path))  \
  }

namespace tessera {

constexpr uint32_t kPluginAbiVersion = TESSERA_PLUGIN_ABI_VERSION;

// Base of every plugin object.
class TESSERA_API Plugin {
 public:
  // Takes the host's services from the factory (TESSERA_PLUGIN), so that a
  // constructor can use host().
  Plugin() : services_(detail::ServicesUnderConstruction()) {}
  virtual ~Plugin() = default;

  // The options in effect, defaults filled in. The host records them with the
  // results this plugin produced, so that a change invalidates those results.
  const nlohmann::json& EffectiveOptions() const { return effective_options_; }

  // The plugin's logger (tessera/log.h): lines go to the host's log with the plugin's
  // name. The host connects it right after the factory returns, so a constructor's
  // lines go to stderr.
  const Logger& log() const { return log_; }
  // For the host: connects log() to the host's log.
  void SetLogSink(LogSink sink) { log_.SetSink(std::move(sink)); }

  // The host's services (tessera/plugin_services.h): another plugin by kind, name and
  // options, guarded as the host guards its own. Usable from the constructor on;
  // outside a host every request throws InputError.
  const PluginServices& host() const {
    static const detail::NoHostServices no_host;
    return services_ ? *services_ : no_host;
  }

 protected:
  nlohmann::json effective_options_ = nlohmann::json::object();

 private:
  Logger log_;
  std::shared_ptr<const PluginServices> services_;
};

// Makes a plugin from its options, with the host's services (null: none). Throws
// tessera::OptionError for invalid options.
using PluginFactory = std::unique_ptr<Plugin>(const nlohmann::json& options,
                                              std::shared_ptr<const PluginServices> services);

// Describes a plugin's options: a JSON array of OptionDescription::ToJson()
// (tessera/option_list.h), each default being what the plugin uses when the option is
// not given. Called without constructing the plugin; must not throw.
using PluginOptionsDescriber = nlohmann::json();

}  // namespace tessera

// Defines the info record and the factory of a plugin. KIND is one of detector,
// matcher, pair_selector, mapper, bundle_adjuster, exporter; CLASS derives from that kind's
// interface and has a constructor taking `const nlohmann::json& options`.
//
//   TESSERA_PLUGIN(detector, SiftDetector, "sift", "1.0.0", "SIFT (OpenCV)")
#define TESSERA_PLUGIN(KIND, CLASS, NAME, VERSION, DESCRIPTION)                                   \
  static_assert(std::is_base_of_v<::tessera::plugin_kinds::KIND, CLASS>,                          \
                #CLASS " must derive from the " #KIND " interface");                              \
  extern "C" {                                                                                    \
  const TesseraPluginInfo tessera_plugin_info_record = {                                          \
      TESSERA_PLUGIN_ABI_VERSION, #KIND, NAME, VERSION, DESCRIPTION, TESSERA_BUILD_RECORD};       \
  }                                                                                               \
  static std::unique_ptr<::tessera::Plugin> tessera_plugin_create_impl(                           \
      const nlohmann::json& options, std::shared_ptr<const ::tessera::PluginServices> services) { \
    const ::tessera::detail::ServicesUnderConstructionScope scope(std::move(services));           \
    return std::make_unique<CLASS>(options);                                                      \
  }                                                                                               \
  BOOST_DLL_ALIAS(tessera_plugin_info_record, tessera_plugin_info)                                \
  BOOST_DLL_ALIAS(tessera_plugin_create_impl, tessera_plugin_create)

// Exports the description of a plugin's options (symbol tessera_plugin_options), from the
// option list that its constructor reads them with (tessera/option_list.h): OPTIONS is the
// options struct, whose default-constructed values are the defaults, and VISIT the
// function template that lists its fields.
//
//   TESSERA_PLUGIN_OPTIONS(tessera::SiftOptions, tessera::VisitSiftOptions)
#define TESSERA_PLUGIN_OPTIONS(OPTIONS, VISIT)                               \
  static nlohmann::json tessera_plugin_options_impl() {                      \
    return ::tessera::option_list::DescribeAsJson<OPTIONS>(                  \
        [](OPTIONS& options, const auto& visit) { VISIT(options, visit); }); \
  }                                                                          \
  BOOST_DLL_ALIAS(tessera_plugin_options_impl, tessera_plugin_options)

// The same, for a plugin whose options another function describes (a host options
// struct's Describe(), as the mappers' are): FUNCTION returns the JSON array.
#define TESSERA_PLUGIN_OPTIONS_FROM(FUNCTION)                                \
  static nlohmann::json tessera_plugin_options_impl() { return FUNCTION(); } \
  BOOST_DLL_ALIAS(tessera_plugin_options_impl, tessera_plugin_options)
